// The swarm run viewer's page script: loads a run's scene and frames from the viewer's HTTP API (/api/...),
// draws them on the #arena canvas, replays or follows the run, and exposes `window.viewer` for the tests.
'use strict';

(() => {
  // ------------------------------------------------------------------------------------------------ state

  const CHUNK = 64;                  // frames per /api/frames request
  const MAX_CHUNKS = 40;             // chunks kept in the LRU cache
  const MAX_IN_FLIGHT = 2;           // frame chunk requests at once
  const SCRUB_INTERVAL_MS = 100;     // the scrubber seeks at most this often while dragged
  const ROBOT_INTERVAL_MS = 200;     // at most 5 robot panel requests per second
  const TRAIL_FRAMES = 60;
  const MIN_ROBOT_PX = 3;
  const CLICK_SLOP_PX = 4;
  const DEFAULT_TPS = 10;
  const DEFAULT_RADIUS = 0.035;
  const PRESENT = 1, ALIVE = 2, FROZEN = 4, CARRYING = 8;

  const $ = (id) => document.getElementById(id);
  const el = {
    dir: $('dir'), robotCount: $('robot-count'), tick: $('tick'), time: $('time'), live: $('live'),
    problem: $('problem'), stage: $('stage'), arena: $('arena'), loading: $('loading'),
    play: $('play'), stepBack: $('step-back'), step: $('step'), speed: $('speed'), trail: $('trail'),
    follow: $('follow'), markers: $('markers'), scrubber: $('scrubber'),
    panel: $('robot-panel'), robotClose: $('robot-close'), robotId: $('robot-id'), robotIndex: $('robot-index'),
    robotController: $('robot-controller'), robotBody: $('robot-body'), robotState: $('robot-state'),
    robotProblem: $('robot-problem'), robotAt: $('robot-at'),
    supervisors: document.querySelector('#robot-supervisors tbody'), events: $('robot-events'),
  };
  const ctx = el.arena.getContext('2d');

  const run = {
    info: null,         // the last /api/run answer
    scene: null,
    tps: DEFAULT_TPS,
    robots: 0,
    first: null,        // complete ticks first..last; null while there are none
    last: null,
    radii: [],          // robot index -> radius (m)
    floor: null,        // the loaded floor image
  };
  const problems = { fromRun: [], fromPage: new Map() };   // page problems by what failed
  const play = { playing: false, speed: 1, stride: 1, playhead: 0, lastTime: 0 };
  const live = { source: null, following: false, finished: false, newest: null };
  const view = { scale: 1, ox: 0, oy: 0, width: 0, height: 0, dpr: 1, userMoved: false, drawQueued: false };
  const counts = { draws: 0, ticksShown: 0 };   // for the benchmark that plays a long run
  const trail = { seconds: 5, frames: [], busy: false, forTick: null, forSeconds: null };
  const selection = { index: null, answer: null, busy: false, lastAt: -Infinity, timer: null, failedFor: null };
  const scrub = { timer: null, lastAt: -Infinity };
  const waiters = { displayed: [], selected: [], liveTick: [], pheromone: [], objects: [] };
  const pheromone = { forTick: null, busy: false, tick: null, cells: 0, canvas: null };
  // Where targets and movable obstacles are at the shown tick (/api/objects), by index: [x, y, angle, in_arena].
  const objects = { forTick: null, busy: false, tick: null, targets: new Map(), obstacles: new Map() };
  let shown = null;      // the displayed frame: {tick, n, f32, u8}
  let wanted = null;     // the tick the page is trying to display
  let markers = [];
  let resolveReady;
  const ready = new Promise((resolve) => { resolveReady = resolve; });

  function liveRunning() {
    return Boolean(run.info && run.info.live) && !live.finished;
  }

  // ------------------------------------------------------------------------------------------------ data

  // Fetches `url`; answers null (and puts the failure in the banner under `what`) instead of throwing.
  async function get(url, what, kind) {
    try {
      const response = await fetch(url);
      if (!response.ok) {
        const text = (await response.text()).trim();
        reportProblem(what, `${what}: ${response.status} ${response.statusText}${text ? ': ' + text : ''}`);
        return null;
      }
      const body = kind === 'json' ? await response.json() : await response.arrayBuffer();
      clearProblem(what);
      return body;
    } catch (error) {
      reportProblem(what, `${what}: ${error.message}`);
      return null;
    }
  }

  // The /api/frames layout: u32 robots, u32 frames, then per frame u32 tick and 16-byte robot records. The typed
  // arrays view the buffer in place (records are 4-byte aligned; every browser platform is little-endian).
  function decodeFrames(buffer) {
    if (buffer.byteLength < 8) return [];
    const data = new DataView(buffer);
    const n = data.getUint32(0, true), count = data.getUint32(4, true);
    const size = 4 + 16 * n;
    const frames = [];
    for (let i = 0; i < count && 8 + (i + 1) * size <= buffer.byteLength; i++) {
      const at = 8 + i * size;
      frames.push({
        tick: data.getUint32(at, true), n,
        f32: new Float32Array(buffer, at + 4, n * 4), u8: new Uint8Array(buffer, at + 4, n * 16),
      });
    }
    return frames;
  }

  function base64ToBuffer(text) {
    const binary = atob(text);
    const bytes = new Uint8Array(binary.length);
    for (let i = 0; i < binary.length; i++) bytes[i] = binary.charCodeAt(i);
    return bytes.buffer;
  }

  // Chunks are aligned on a grid from tick 0: chunk k of stride s holds ticks k*64*s + j*s. A chunk remembers
  // the newest complete tick when it was asked for (`upTo`): in a live run it may be missing later ticks.
  const chunks = new Map();        // "stride:k" -> {frames: Map tick -> frame, upTo}; Map order is the LRU order
  const inFlight = new Set();
  const failedChunks = new Set();
  const strides = new Set([1]);

  const chunkKey = (stride, k) => `${stride}:${k}`;
  const chunkOf = (tick, stride) => Math.floor(tick / (CHUNK * stride));

  function cachedFrame(tick) {
    for (const stride of strides) {
      if (tick % stride !== 0) continue;
      const key = chunkKey(stride, chunkOf(tick, stride));
      const chunk = chunks.get(key);
      const frame = chunk && chunk.frames.get(tick);
      if (frame) {
        chunks.delete(key);
        chunks.set(key, chunk);
        return frame;
      }
    }
    return live.newest && live.newest.tick === tick ? live.newest : null;
  }

  function chunkNeeded(stride, k) {
    const key = chunkKey(stride, k);
    if (inFlight.has(key) || failedChunks.has(key) || run.last === null) return false;
    const start = k * CHUNK * stride;
    if (start > run.last) return false;
    const chunk = chunks.get(key);
    return !chunk || (chunk.upTo < run.last && chunk.upTo < start + (CHUNK - 1) * stride);
  }

  function requestChunk(stride, k) {
    if (inFlight.size >= MAX_IN_FLIGHT || !chunkNeeded(stride, k)) return;
    const key = chunkKey(stride, k);
    const upTo = run.last;
    inFlight.add(key);
    strides.add(stride);
    get(`/api/frames?from=${k * CHUNK * stride}&count=${CHUNK}&stride=${stride}`, 'frames').then((buffer) => {
      inFlight.delete(key);
      if (buffer) {
        storeChunk(key, decodeFrames(buffer), upTo);
      } else {
        failedChunks.add(key);
        resolveReady();
      }
      showWanted();
    });
  }

  function storeChunk(key, frames, upTo) {
    chunks.delete(key);
    chunks.set(key, { frames: new Map(frames.map((frame) => [frame.tick, frame])), upTo });
    while (chunks.size > MAX_CHUNKS) chunks.delete(chunks.keys().next().value);
  }

  // Shows the wanted tick if it is loaded, otherwise asks for it (the last frame stays on screen meanwhile).
  function showWanted() {
    if (wanted === null) return;
    const frame = cachedFrame(wanted);
    if (frame && frame !== shown) display(frame);
    if (!frame) {
      const stride = wanted % play.stride === 0 ? play.stride : 1;
      requestChunk(stride, chunkOf(wanted, stride));
    }
    if (play.playing) requestChunk(play.stride, chunkOf(wanted, play.stride) + 1);
    el.loading.hidden = frame !== null || run.last === null;
  }

  function requestTrail() {
    if (trail.busy || !shown || trail.seconds === 0) return;
    const tick = shown.tick, seconds = trail.seconds;
    if (trail.forTick === tick && trail.forSeconds === seconds) return;
    const length = Math.round(seconds * run.tps);
    const from = Math.max(run.first ?? 0, tick - length);
    const stride = Math.max(1, Math.ceil(length / TRAIL_FRAMES));
    trail.busy = true;
    get(`/api/frames?from=${from}&count=${TRAIL_FRAMES}&stride=${stride}`, 'trails').then((buffer) => {
      Object.assign(trail, { busy: false, forTick: tick, forSeconds: seconds, frames: buffer ? decodeFrames(buffer) : [] });
      requestDraw();
      requestTrail();
    });
  }

  // The pheromone field under the robots: the frame recorded last at or before the displayed tick (the world
  // records one per simulated second), one request at a time.
  function requestPheromone() {
    const layout = run.scene && run.scene.pheromone;
    if (!layout || !shown || pheromone.busy) return;
    const tick = Math.floor(shown.tick / layout.every) * layout.every;
    if (pheromone.forTick === tick) return;
    pheromone.busy = true;
    get(`/api/pheromone?tick=${tick}`, 'pheromone').then((buffer) => {
      pheromone.busy = false;
      pheromone.forTick = tick;
      if (buffer && buffer.byteLength > 8) paintPheromone(layout, buffer);
      requestDraw();
      settle(waiters.pheromone, (w) => w.tick === pheromone.tick);
      requestPheromone();
    });
  }

  // Targets and movable obstacles at the displayed tick, one request at a time; scene poses until it answers.
  function requestObjects() {
    if (!run.scene || !shown || objects.busy || objects.forTick === shown.tick) return;
    const tick = shown.tick;
    objects.busy = true;
    get(`/api/objects?tick=${tick}`, 'objects', 'json').then((reply) => {
      objects.busy = false;
      objects.forTick = tick;
      if (reply) {
        const byIndex = (rows) => new Map(rows.map(([index, ...pose]) => [index, pose]));
        Object.assign(objects, { tick, targets: byIndex(reply.targets), obstacles: byIndex(reply.obstacles) });
        requestDraw();
        settle(waiters.objects, (w) => w.tick === tick);
      }
      requestObjects();
    });
  }

  // `body` of the scene where /api/objects last put it, or null when it is out of the arena.
  function placed(body, pose) {
    if (!pose) return body;
    const [x, y, angle, inArena] = pose;
    return inArena ? { ...body, x, y, angle } : null;
  }

  // Turns a frame (u64 tick, then per channel, per row from the lowest y, one byte per cell) into an image whose
  // row 0 is the top; each cell takes the colour of its strongest channel, more opaque as it is stronger.
  function paintPheromone({ nx, ny, channels, colours }, buffer) {
    const cells = new Uint8Array(buffer, 8);
    const canvas = pheromone.canvas || (pheromone.canvas = document.createElement('canvas'));
    canvas.width = nx;
    canvas.height = ny;
    const painter = canvas.getContext('2d');
    const image = painter.createImageData(nx, ny);
    let marked = 0;
    for (let y = 0; y < ny; y++) {
      for (let x = 0; x < nx; x++) {
        let strongest = 0, colour = null;
        for (let ch = 0; ch < channels; ch++) {
          const value = cells[(ch * ny + y) * nx + x];
          if (value > strongest) { strongest = value; colour = colours[ch]; }
        }
        if (!colour) continue;
        marked++;
        image.data.set([...colour, Math.round(strongest * 200 / 255)], ((ny - 1 - y) * nx + x) * 4);
      }
    }
    painter.putImageData(image, 0, 0);
    pheromone.tick = Number(new DataView(buffer).getBigUint64(0, true));
    pheromone.cells = marked;
  }

  // The selected robot's panel follows the displayed tick: one request at a time, at most 5 a second, and the
  // newest wanted tick wins.
  function requestRobot() {
    if (selection.index === null || !shown || selection.busy) return;
    const index = selection.index, tick = shown.tick, key = `${index}@${tick}`;
    const answer = selection.answer;
    if ((answer && answer.index === index && answer.tick === tick) || selection.failedFor === key) return;
    const wait = selection.lastAt + ROBOT_INTERVAL_MS - performance.now();
    if (wait > 0) {
      if (selection.timer === null) selection.timer = setTimeout(() => { selection.timer = null; requestRobot(); }, wait);
      return;
    }
    selection.busy = true;
    selection.lastAt = performance.now();
    get(`/api/robot/${index}?at=${tick}`, 'robot', 'json').then((reply) => {
      selection.busy = false;
      selection.failedFor = reply ? null : key;
      if (reply && reply.index === selection.index) showRobot(reply);
      requestRobot();
    });
  }

  async function loadTimeline() {
    const timeline = await get('/api/timeline', 'timeline', 'json');
    if (!timeline) return;
    markers = timeline.markers || [];
    renderMarkers();
  }

  async function refreshRun() {
    const info = await get('/api/run', 'run', 'json');
    if (info) applyRun(info);
  }

  async function start() {
    const info = await get('/api/run', 'run', 'json');
    if (!info) {
      resolveReady();
      return;
    }
    applyRun(info);
    applyScene(info.scene);
    fitView();
    render();
    loadTimeline();
    if (liveRunning()) startLive();
    if (run.last === null) {
      resolveReady();
      return;
    }
    seekTo(liveRunning() ? run.last : run.first, { keepFollowing: true });
  }

  function applyRun(info) {
    run.info = info;
    run.robots = info.robots || 0;
    if (info.ticks) {
      run.first = info.ticks.first;
      run.last = Math.max(run.last ?? info.ticks.last, info.ticks.last);
    }
    problems.fromRun = info.problems || [];
    if (info.finished) live.finished = true;
    el.dir.textContent = info.dir || '';
    el.robotCount.textContent = String(run.robots);
    updateRange();
    renderProblems();
    updateLiveControls();
  }

  function applyScene(scene) {
    run.scene = scene;
    if (!scene) return;
    run.tps = scene.ticks_per_second || DEFAULT_TPS;
    for (const robot of scene.robots || []) run.radii[robot.index] = robot.radius;
    if (scene.floor) {
      const image = new Image();
      image.onload = () => { run.floor = image; requestDraw(); };
      image.onerror = () => reportProblem('floor', 'floor: /api/floor.png could not be loaded');
      image.src = '/api/floor.png';
    }
    setSpeed(play.speed);
  }

  // ------------------------------------------------------------------------------------------------ display

  function setWanted(tick) {
    wanted = tick;
    el.scrubber.value = String(tick);
  }

  function display(frame) {
    const changed = !shown || shown.tick !== frame.tick;
    const first = !shown;
    shown = frame;
    if (first && !run.scene) fitView();
    render();
    if (changed) {
      counts.ticksShown++;
      el.tick.textContent = String(frame.tick);
      el.time.textContent = (frame.tick / run.tps).toFixed(2);
      requestTrail();
      requestRobot();
      requestPheromone();
      requestObjects();
    }
    updateRobotState();
    resolveReady();
    settle(waiters.displayed, (w) => w.tick === frame.tick);
    if (run.info && run.info.live) settle(waiters.liveTick, (w) => frame.tick >= w.tick);
  }

  // Resolves (and forgets) the waiters that `done` accepts.
  function settle(list, done) {
    for (let i = list.length - 1; i >= 0; i--) {
      if (done(list[i])) {
        list[i].resolve();
        list.splice(i, 1);
      }
    }
  }

  function robotAt(frame, i) {
    const flags = frame.u8[i * 16 + 15];
    return {
      index: i, x: frame.f32[i * 4], y: frame.f32[i * 4 + 1], heading: frame.f32[i * 4 + 2],
      present: Boolean(flags & PRESENT), alive: Boolean(flags & ALIVE),
      frozen: Boolean(flags & FROZEN), carrying: Boolean(flags & CARRYING),
      led: [frame.u8[i * 16 + 12], frame.u8[i * 16 + 13], frame.u8[i * 16 + 14]],
    };
  }

  // ------------------------------------------------------------------------------------------------ drawing

  const sx = (x) => view.ox + x * view.scale;
  const sy = (y) => view.oy - y * view.scale;

  function requestDraw() {
    if (view.drawQueued) return;
    view.drawQueued = true;
    requestAnimationFrame(() => { view.drawQueued = false; render(); });
  }

  function render() {
    if (view.width === 0 || view.height === 0) return;
    counts.draws++;
    ctx.setTransform(view.dpr, 0, 0, view.dpr, 0, 0);
    ctx.clearRect(0, 0, view.width, view.height);
    drawArena();
    drawPheromone();
    if (run.scene) {
      (run.scene.targets || []).forEach((target, i) => {
        const body = placed(target, objects.targets.get(i));
        if (body) drawBody(body, targetColour(target.colour));
      });
      (run.scene.obstacles || []).forEach((obstacle, i) => {
        const body = placed(obstacle, objects.obstacles.get(i));
        if (body) drawBody(body, obstacle.movable ? '#8b7d70' : '#454545');
      });
      drawLights();
    }
    if (shown) {
      drawTrails();
      drawRobots();
    }
    drawScaleBar();
  }

  function drawPheromone() {
    const layout = run.scene && run.scene.pheromone;
    if (!layout || pheromone.tick === null) return;
    const side = layout.cell * view.scale;
    ctx.imageSmoothingEnabled = false;
    ctx.drawImage(pheromone.canvas, sx(layout.min[0]), sy(layout.min[1] + layout.ny * layout.cell),
      layout.nx * side, layout.ny * side);
  }

  function drawArena() {
    const arena = run.scene && run.scene.arena;
    if (!arena) return;
    const x = sx(arena.min[0]), y = sy(arena.max[1]);
    const w = (arena.max[0] - arena.min[0]) * view.scale, h = (arena.max[1] - arena.min[1]) * view.scale;
    ctx.fillStyle = '#f7f7f4';
    ctx.fillRect(x, y, w, h);
    const floor = run.scene.floor;
    if (floor && run.floor) {
      ctx.imageSmoothingEnabled = false;
      ctx.drawImage(run.floor, sx(floor.min[0]), sy(floor.max[1]),
        (floor.max[0] - floor.min[0]) * view.scale, (floor.max[1] - floor.min[1]) * view.scale);
    }
    ctx.strokeStyle = '#1b1b1b';
    ctx.lineWidth = 2;
    ctx.strokeRect(x, y, w, h);
  }

  function targetColour([r, g, b]) {
    return r === 0 && g === 0 && b === 0 ? 'rgb(200,0,0)' : `rgb(${r},${g},${b})`;
  }

  function drawBody(body, fill) {
    ctx.save();
    ctx.translate(sx(body.x), sy(body.y));
    ctx.rotate(-(body.angle || 0));   // CCW in the world is CCW on screen, whose y axis points down
    ctx.beginPath();
    if (body.shape === 'disc') {
      ctx.arc(0, 0, body.radius * view.scale, 0, 2 * Math.PI);
    } else {
      const [hx, hy] = body.half;
      ctx.rect(-hx * view.scale, -hy * view.scale, 2 * hx * view.scale, 2 * hy * view.scale);
    }
    ctx.fillStyle = fill;
    ctx.fill();
    ctx.restore();
  }

  function drawLights() {
    for (const light of run.scene.lights || []) {
      const x = sx(light.x), y = sy(light.y);
      const core = Math.max(3, 0.05 * view.scale), halo = Math.max(16, core * 4);
      const glow = ctx.createRadialGradient(x, y, core, x, y, halo);
      glow.addColorStop(0, 'rgba(255,230,80,0.45)');
      glow.addColorStop(1, 'rgba(255,230,80,0)');
      ctx.fillStyle = glow;
      ctx.beginPath();
      ctx.arc(x, y, halo, 0, 2 * Math.PI);
      ctx.fill();
      ctx.fillStyle = 'rgb(255,215,0)';
      ctx.strokeStyle = 'rgba(120,90,0,0.8)';
      ctx.lineWidth = 1;
      ctx.beginPath();
      ctx.arc(x, y, core, 0, 2 * Math.PI);
      ctx.fill();
      ctx.stroke();
    }
  }

  function drawTrails() {
    if (trail.seconds === 0) return;
    const oldest = shown.tick - trail.seconds * run.tps;
    const frames = trail.frames.filter((f) => f.tick >= oldest && f.tick < shown.tick && f.n === shown.n);
    if (frames.length === 0) return;
    frames.push(shown);
    ctx.beginPath();
    for (let i = 0; i < shown.n; i++) {
      let drawing = false;
      for (const frame of frames) {
        if (!(frame.u8[i * 16 + 15] & PRESENT)) {
          drawing = false;
          continue;
        }
        const x = sx(frame.f32[i * 4]), y = sy(frame.f32[i * 4 + 1]);
        if (drawing) ctx.lineTo(x, y);
        else ctx.moveTo(x, y);
        drawing = true;
      }
    }
    ctx.strokeStyle = 'rgba(30,90,230,0.45)';
    ctx.lineWidth = 1.2;
    ctx.stroke();
  }

  function drawnRadius(i) {
    return Math.max(MIN_ROBOT_PX, (run.radii[i] ?? DEFAULT_RADIUS) * view.scale);
  }

  function drawRobots() {
    const { f32, u8 } = shown;
    ctx.lineWidth = 1;
    for (let i = 0; i < shown.n; i++) {
      const flags = u8[i * 16 + 15];
      if (!(flags & PRESENT)) continue;
      const x = sx(f32[i * 4]), y = sy(f32[i * 4 + 1]), heading = f32[i * 4 + 2], r = drawnRadius(i);
      ctx.beginPath();
      ctx.arc(x, y, r, 0, 2 * Math.PI);
      ctx.fillStyle = flags & ALIVE ? ledColour(u8, i) : 'rgb(60,60,60)';
      ctx.fill();
      ctx.moveTo(x, y);
      ctx.lineTo(x + Math.cos(heading) * r, y - Math.sin(heading) * r);
      ctx.strokeStyle = '#000';
      ctx.stroke();
      if (flags & FROZEN) ring(x, y, r + 2, 'rgb(0,200,230)', 3);
      if (flags & CARRYING) {
        ctx.beginPath();
        ctx.arc(x, y, Math.max(1.5, r * 0.3), 0, 2 * Math.PI);
        ctx.fillStyle = 'rgb(220,0,0)';
        ctx.fill();
      }
      if (i === selection.index) ring(x, y, r + 5, 'rgb(255,140,0)', 2.5);
    }
  }

  function ledColour(u8, i) {
    const r = u8[i * 16 + 12], g = u8[i * 16 + 13], b = u8[i * 16 + 14];
    return r === 0 && g === 0 && b === 0 ? 'rgb(230,230,230)' : `rgb(${r},${g},${b})`;
  }

  function ring(x, y, radius, colour, width) {
    ctx.beginPath();
    ctx.arc(x, y, radius, 0, 2 * Math.PI);
    ctx.strokeStyle = colour;
    ctx.lineWidth = width;
    ctx.stroke();
    ctx.lineWidth = 1;
  }

  // A bar of a round length (1, 2 or 5 times a power of ten) about 100 px long, in the bottom-left corner.
  function drawScaleBar() {
    if (!run.scene && !shown) return;
    const metres = 100 / view.scale;
    const power = 10 ** Math.floor(Math.log10(metres));
    const length = [5, 2, 1].map((m) => m * power).find((l) => l <= metres);
    const px = length * view.scale, x = 14, y = view.height - 16;
    const label = length >= 1 ? `${length} m` : length >= 0.01 ? `${+(length * 100).toFixed(2)} cm` : `${+(length * 1000).toFixed(2)} mm`;
    ctx.fillStyle = 'rgba(0,0,0,0.55)';
    ctx.fillRect(x - 6, y - 22, px + 12, 30);
    ctx.strokeStyle = '#fff';
    ctx.lineWidth = 2;
    ctx.beginPath();
    ctx.moveTo(x, y - 5);
    ctx.lineTo(x, y);
    ctx.lineTo(x + px, y);
    ctx.lineTo(x + px, y - 5);
    ctx.stroke();
    ctx.fillStyle = '#fff';
    ctx.font = '12px "DejaVu Sans", sans-serif';
    ctx.fillText(label, x, y - 8);
  }

  // The arena, or without a scene the robots of the displayed frame.
  function worldBounds() {
    const arena = run.scene && run.scene.arena;
    if (arena) return { min: arena.min, max: arena.max };
    if (!shown) return null;
    const min = [Infinity, Infinity], max = [-Infinity, -Infinity];
    for (let i = 0; i < shown.n; i++) {
      const robot = robotAt(shown, i);
      if (!robot.present) continue;
      min[0] = Math.min(min[0], robot.x - 0.5); min[1] = Math.min(min[1], robot.y - 0.5);
      max[0] = Math.max(max[0], robot.x + 0.5); max[1] = Math.max(max[1], robot.y + 0.5);
    }
    return min[0] < max[0] ? { min, max } : null;
  }

  function fitView() {
    const bounds = worldBounds();
    if (!bounds || view.width === 0) return;
    const margin = 16;
    const w = bounds.max[0] - bounds.min[0], h = bounds.max[1] - bounds.min[1];
    view.scale = Math.max(1e-6, Math.min((view.width - 2 * margin) / w, (view.height - 2 * margin) / h));
    view.ox = view.width / 2 - (bounds.min[0] + w / 2) * view.scale;
    view.oy = view.height / 2 + (bounds.min[1] + h / 2) * view.scale;
    view.userMoved = false;
  }

  function resize() {
    const rect = el.arena.getBoundingClientRect();
    view.dpr = window.devicePixelRatio || 1;
    view.width = rect.width;
    view.height = rect.height;
    el.arena.width = Math.round(rect.width * view.dpr);
    el.arena.height = Math.round(rect.height * view.dpr);
    if (!view.userMoved) fitView();
    render();
  }

  // ------------------------------------------------------------------------------------------------ page parts

  function reportProblem(what, message) {
    problems.fromPage.set(what, message);
    renderProblems();
  }

  function clearProblem(what) {
    if (problems.fromPage.delete(what)) renderProblems();
  }

  function allProblems() {
    return [...problems.fromRun, ...problems.fromPage.values()];
  }

  function renderProblems() {
    const list = allProblems();
    el.problem.hidden = list.length === 0;
    const items = list.map((text) => {
      const item = document.createElement('li');
      item.textContent = text;
      return item;
    });
    const ul = document.createElement('ul');
    ul.append(...items);
    el.problem.replaceChildren(ul);
  }

  function updateRange() {
    el.scrubber.min = String(run.first ?? 0);
    el.scrubber.max = String(run.last ?? 0);
    el.scrubber.disabled = run.last === null;
    if (wanted !== null) el.scrubber.value = String(wanted);
    positionMarkers();
  }

  function updateLiveControls() {
    const isLive = Boolean(run.info && run.info.live);
    el.live.hidden = !isLive;
    el.live.textContent = live.finished ? 'finished' : 'LIVE';
    el.live.classList.toggle('finished', live.finished);
    el.follow.hidden = !liveRunning();
    el.follow.classList.toggle('active', live.following);
    el.play.textContent = play.playing || live.following ? '❚❚' : '▶';
  }

  function markerColour(what) {
    if (['fault:kill', 'fault:down', 'fault:host-lost'].includes(what)) return 'rgb(230,40,40)';
    if (what === 'fault:freeze') return 'rgb(0,210,230)';
    if (['fault:up', 'fault:thaw', 'join'].includes(what)) return 'rgb(40,200,70)';
    return 'rgb(150,150,150)';
  }

  function renderMarkers() {
    el.markers.replaceChildren(...markers.map((marker) => {
      const mark = document.createElement('span');
      mark.className = 'marker';
      mark.dataset.tick = String(marker.tick);
      mark.style.background = markerColour(marker.what);
      mark.title = `tick ${marker.tick}: ${marker.id ?? 'robot ' + marker.robot} ${marker.what}`;
      return mark;
    }));
    positionMarkers();
  }

  // Lines the marks up with the scrubber's thumb positions (the thumb's centre travels inside half a thumb).
  function positionMarkers() {
    const span = Math.max(1, (run.last ?? 0) - (run.first ?? 0));
    for (const mark of el.markers.children) {
      const fraction = Math.min(1, Math.max(0, (Number(mark.dataset.tick) - (run.first ?? 0)) / span));
      mark.style.left = `calc(var(--thumb) / 2 + (100% - var(--thumb)) * ${fraction})`;
    }
  }

  function selectRobot(index) {
    selection.index = index;
    selection.answer = null;
    selection.failedFor = null;
    el.panel.hidden = index === null;
    if (index !== null) {
      const info = run.scene && (run.scene.robots || []).find((robot) => robot.index === index);
      showRobotInfo(info || { index, id: '', controller: '', body: '' });
      el.robotAt.textContent = '';
      el.robotProblem.hidden = true;
      el.supervisors.replaceChildren();
      el.events.replaceChildren();
      updateRobotState();
      requestRobot();
    }
    render();
  }

  function showRobotInfo({ index, id, controller, body }) {
    el.robotId.textContent = id;
    el.robotIndex.textContent = String(index);
    el.robotController.textContent = controller;
    el.robotBody.textContent = body;
  }

  function updateRobotState() {
    if (selection.index === null || !shown) return;
    const robot = selection.index < shown.n ? robotAt(shown, selection.index) : null;
    el.robotState.textContent = !robot || !robot.present ? 'not in the run'
      : robot.frozen ? 'frozen' : robot.alive ? 'alive' : 'dead';
  }

  function showRobot(answer) {
    selection.answer = answer;
    showRobotInfo(answer);
    el.robotAt.textContent = `after tick ${answer.tick}`;
    el.robotProblem.hidden = !answer.problem;
    el.robotProblem.textContent = answer.problem || '';
    el.supervisors.replaceChildren(...answer.supervisors.map((supervisor) => {
      const row = document.createElement('tr');
      row.className = 'supervisor';
      row.dataset.name = supervisor.name;
      row.dataset.state = String(supervisor.state);
      const name = document.createElement('td'), state = document.createElement('td');
      name.textContent = supervisor.name;
      state.textContent = `state ${supervisor.state} of ${supervisor.states}`;
      row.append(name, state);
      return row;
    }));
    el.events.replaceChildren(...answer.events.map(([tick, name]) => {
      const item = document.createElement('li');
      item.textContent = `${tick} ${name}`;
      return item;
    }));
    el.events.scrollTop = el.events.scrollHeight;
    settle(waiters.selected, (w) => w.index === answer.index && w.tick === answer.tick);
  }

  // ------------------------------------------------------------------------------------------------ playback

  function seekTo(tick, { keepFollowing = false } = {}) {
    if (run.last === null) return;
    if (!keepFollowing) stopFollowing();
    const clamped = Math.min(run.last, Math.max(run.first, Math.round(tick)));
    play.playhead = clamped;
    setWanted(clamped);
    showWanted();
  }

  function stepBy(delta) {
    if (run.last === null) return;
    setPlaying(false);
    seekTo((wanted ?? run.first) + delta);
  }

  function togglePlay() {
    if (live.following) stopFollowing();
    else setPlaying(!play.playing);
  }

  function setPlaying(on) {
    if (on === play.playing || (on && run.last === null)) return;
    play.playing = on;
    if (on) {
      if (!liveRunning() && wanted >= run.last) seekTo(run.first);
      play.playhead = wanted;
      play.lastTime = performance.now();
      requestAnimationFrame(playStep);
    }
    updateLiveControls();
  }

  function playStep(now) {
    if (!play.playing) return;
    const seconds = Math.min(0.25, Math.max(0, (now - play.lastTime) / 1000));
    play.lastTime = now;
    play.playhead = Math.min(run.last, play.playhead + play.speed * run.tps * seconds);
    if (play.playhead >= run.last && !liveRunning()) {
      setWanted(run.last);
      setPlaying(false);
    } else {
      const tick = Math.floor(play.playhead / play.stride) * play.stride;
      setWanted(Math.max(run.first, tick));
    }
    showWanted();
    if (play.playing) requestAnimationFrame(playStep);
  }

  // Ticks per displayed animation frame (at 60 Hz) decide the stride: a power of two no larger, so that the
  // chunks stay on one grid and a chunk lasts half a second to a second of playback.
  function setSpeed(speed) {
    play.speed = speed;
    const perFrame = speed * run.tps / 60;
    play.stride = perFrame < 2 ? 1 : 2 ** Math.floor(Math.log2(perFrame));
  }

  function setTrail(seconds) {
    trail.seconds = seconds;
    trail.frames = [];
    trail.forTick = null;
    requestTrail();
    render();
  }

  // ------------------------------------------------------------------------------------------------ interaction

  function localPoint(event) {
    const rect = el.arena.getBoundingClientRect();
    return { x: event.clientX - rect.left, y: event.clientY - rect.top };
  }

  // The robot whose drawn disc (plus 3 px) holds the point, nearest centre first; null for none.
  function robotUnder(point) {
    if (!shown) return null;
    let best = null, bestDistance = Infinity;
    for (let i = 0; i < shown.n; i++) {
      if (!(shown.u8[i * 16 + 15] & PRESENT)) continue;
      const distance = Math.hypot(sx(shown.f32[i * 4]) - point.x, sy(shown.f32[i * 4 + 1]) - point.y);
      if (distance <= drawnRadius(i) + 3 && distance < bestDistance) {
        best = i;
        bestDistance = distance;
      }
    }
    return best;
  }

  function installPointer() {
    let press = null;
    el.arena.addEventListener('pointerdown', (event) => {
      if (event.button !== 0) return;
      press = { start: localPoint(event), last: localPoint(event), dragging: false };
      el.arena.setPointerCapture(event.pointerId);
    });
    el.arena.addEventListener('pointermove', (event) => {
      if (!press) return;
      const point = localPoint(event);
      if (!press.dragging && Math.hypot(point.x - press.start.x, point.y - press.start.y) >= CLICK_SLOP_PX) {
        press.dragging = true;
        el.arena.classList.add('dragging');
      }
      if (press.dragging) {
        view.ox += point.x - press.last.x;
        view.oy += point.y - press.last.y;
        view.userMoved = true;
        requestDraw();
      }
      press.last = point;
    });
    el.arena.addEventListener('pointerup', (event) => {
      if (!press) return;
      if (!press.dragging) selectRobot(robotUnder(localPoint(event)));
      el.arena.classList.remove('dragging');
      press = null;
    });
    el.arena.addEventListener('pointercancel', () => {
      el.arena.classList.remove('dragging');
      press = null;
    });
    el.arena.addEventListener('wheel', (event) => {
      event.preventDefault();
      const point = localPoint(event);
      const factor = Math.exp(-event.deltaY * 0.0015);
      view.ox = point.x - (point.x - view.ox) * factor;
      view.oy = point.y - (point.y - view.oy) * factor;
      view.scale *= factor;
      view.userMoved = true;
      requestDraw();
    }, { passive: false });
    el.arena.addEventListener('dblclick', () => {
      fitView();
      render();
    });
  }

  // The scrubber seeks at once, then at most every SCRUB_INTERVAL_MS while it is dragged, and at the end.
  function onScrub() {
    stopFollowing();
    setPlaying(false);
    clearTimeout(scrub.timer);
    const seek = () => {
      scrub.lastAt = performance.now();
      seekTo(Number(el.scrubber.value));
    };
    const wait = scrub.lastAt + SCRUB_INTERVAL_MS - performance.now();
    if (wait <= 0) seek();
    else scrub.timer = setTimeout(seek, wait);
  }

  function onKey(event) {
    const target = event.target;
    if (event.altKey || event.ctrlKey || event.metaKey || target === el.scrubber || target.tagName === 'SELECT') return;
    if (event.key === 'ArrowLeft') stepBy(-1);
    else if (event.key === 'ArrowRight') stepBy(1);
    else if (event.key === ' ' && target.tagName !== 'BUTTON') togglePlay();
    else return;
    event.preventDefault();
  }

  function installControls() {
    for (const button of document.querySelectorAll('button')) {
      button.addEventListener('mousedown', (event) => event.preventDefault());   // keeps Space for play/pause
    }
    el.play.addEventListener('click', togglePlay);
    el.step.addEventListener('click', () => stepBy(1));
    el.stepBack.addEventListener('click', () => stepBy(-1));
    el.follow.addEventListener('click', follow);
    el.speed.addEventListener('change', () => setSpeed(Number(el.speed.value)));
    el.trail.addEventListener('change', () => setTrail(Number(el.trail.value)));
    el.scrubber.addEventListener('input', onScrub);
    el.markers.addEventListener('click', (event) => {
      if (event.target.dataset.tick !== undefined) seekTo(Number(event.target.dataset.tick));
    });
    el.robotClose.addEventListener('click', () => selectRobot(null));
    document.addEventListener('keydown', onKey);
    installPointer();
    new ResizeObserver(resize).observe(el.stage);
  }

  // ------------------------------------------------------------------------------------------------ live

  function startLive() {
    live.following = true;
    live.source = new EventSource('/api/live');
    live.source.addEventListener('frame', (event) => onLiveFrame(JSON.parse(event.data)));
    live.source.addEventListener('open', () => clearProblem('live'));
    live.source.addEventListener('error', () => {
      if (!live.finished) reportProblem('live', 'live: the connection to the run was lost; reconnecting');
    });
    updateLiveControls();
  }

  function onLiveFrame(message) {
    clearProblem('live');
    const frame = decodeFrames(base64ToBuffer(message.frame))[0];
    if (frame) live.newest = frame;
    if (run.last === null) {
      run.first = frame ? frame.tick : message.last;
      refreshRun();   // the first complete tick, which the stream does not say
    }
    run.last = Math.max(run.last ?? message.last, message.last);
    updateRange();
    if (live.following && frame) {
      setWanted(frame.tick);
      display(frame);
      el.loading.hidden = true;
    }
    if (message.finished) finishLive();
  }

  function finishLive() {
    live.finished = true;
    live.following = false;
    live.source.close();
    updateLiveControls();
    refreshRun();
    loadTimeline();
  }

  function follow() {
    if (!liveRunning()) return;
    setPlaying(false);
    live.following = true;
    updateLiveControls();
    if (live.newest) {
      setWanted(live.newest.tick);
      display(live.newest);
      el.loading.hidden = true;
    }
  }

  function stopFollowing() {
    if (!live.following) return;
    live.following = false;
    updateLiveControls();
  }

  // ------------------------------------------------------------------------------------------------ test hooks

  function waitFor(list, fields, now) {
    if (now) return Promise.resolve();
    return new Promise((resolve) => list.push({ ...fields, resolve }));
  }

  window.viewer = {
    ready,
    problems: () => allProblems(),
    tick: () => (shown ? shown.tick : null),
    robots: () => (shown ? Array.from({ length: shown.n }, (_, i) => robotAt(shown, i)) : []),
    seek(tick) {
      setPlaying(false);
      seekTo(tick);
    },
    whenDisplayed: (tick) => waitFor(waiters.displayed, { tick }, shown !== null && shown.tick === tick),
    screenOf(index) {
      if (!shown) return null;
      const rect = el.arena.getBoundingClientRect();
      return { x: rect.left + sx(shown.f32[index * 4]), y: rect.top + sy(shown.f32[index * 4 + 1]) };
    },
    selected() {
      if (selection.index === null) return null;
      const rows = [...el.supervisors.querySelectorAll('tr.supervisor')];
      return {
        index: selection.index,
        tick: selection.answer ? selection.answer.tick : null,
        supervisors: rows.map((row) => ({ name: row.dataset.name, state: Number(row.dataset.state) })),
      };
    },
    whenSelected: (index, tick) => waitFor(waiters.selected, { index, tick },
      selection.answer !== null && selection.answer.index === index && selection.answer.tick === tick),
    live: () => ({
      live: Boolean(run.info && run.info.live), following: live.following, finished: live.finished, last: run.last,
    }),
    pheromone: () => ({ tick: pheromone.tick, cells: pheromone.cells }),
    counts: () => ({ ...counts }),
    objects: () => ({ tick: objects.tick, targets: [...objects.targets], obstacles: [...objects.obstacles] }),
    whenObjects: (tick) => waitFor(waiters.objects, { tick }, objects.tick === tick),
    whenPheromone: (tick) => waitFor(waiters.pheromone, { tick }, pheromone.tick === tick),
    whenLiveTick: (tick) => waitFor(waiters.liveTick, { tick },
      shown !== null && Boolean(run.info && run.info.live) && shown.tick >= tick),
  };

  installControls();
  start();
})();
