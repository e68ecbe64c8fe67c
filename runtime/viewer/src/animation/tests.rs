use std::fs;
use std::path::Path;

use super::*;

/// A run by hand: an arena 1 m by 0.5 m, 100 x 50 pixels at `width_px` 100; robot 0 red at (-0.2, 0.1), robot 1
/// blue at (0.2, -0.1), both heading +x, robot 1 dead from tick 2; ticks 0 to 3.
fn tiny_run(dir: &Path, pheromone: bool) {
    let field = if pheromone {
        r#"{"file": "pheromone.bin", "min": [-0.5, -0.25], "cell": 0.5, "nx": 2, "ny": 1, "channels": 1,
            "every": 2, "colours": [[0, 255, 0]]}"#
    } else {
        "null"
    };
    let scene = format!(
        r#"{{"format": 1, "arena": {{"min": [-0.5, -0.25], "max": [0.5, 0.25]}}, "ticks_per_second": 10,
            "robots": [{{"index": 0, "id": "r0", "controller": "c", "body": "e-puck", "radius": 0.05}},
                       {{"index": 1, "id": "r1", "controller": "c", "body": "e-puck", "radius": 0.05}}],
            "coordinators": [], "obstacles": [], "targets": [], "lights": [], "floor": null,
            "pheromone": {field}}}"#
    );
    fs::write(dir.join("scene.json"), scene).unwrap();
    let mut trajectory = String::from("tick,robot,robot_id,x,y,heading,led_r,led_g,led_b,alive\n");
    for tick in 0..4 {
        let step = tick as f32 * 0.01;
        let alive = u8::from(tick < 2);
        trajectory.push_str(&format!("{tick},0,r0,{},0.1,0,255,0,0,1\n", -0.2 + step));
        trajectory.push_str(&format!(
            "{tick},1,r1,0.2,{},0,0,0,{},{alive}\n",
            -0.1 - step,
            255 * u32::from(alive)
        ));
    }
    fs::write(dir.join("trajectory.csv"), trajectory).unwrap();
    fs::write(dir.join("events.csv"), "tick,robot,robot_id,event\n").unwrap();
    fs::write(dir.join("summary.json"), "{}").unwrap();
    if pheromone {
        let frames: Vec<u8> = [(0u64, [0u8, 255]), (2, [0, 255])]
            .iter()
            .flat_map(|(tick, cells)| tick.to_le_bytes().into_iter().chain(*cells))
            .collect();
        fs::write(dir.join("pheromone.bin"), frames).unwrap();
    }
}

fn small() -> GifOptions {
    GifOptions {
        width_px: 100,
        ..GifOptions::default()
    }
}

/// A GIF read back: its size, its number of frames and frame `keep` as shown (each frame drawn over the ones
/// before), RGBA.
struct Decoded {
    width: usize,
    height: usize,
    frames: usize,
    picture: Vec<u8>,
}

impl Decoded {
    fn read(path: &Path, keep: usize) -> Decoded {
        let mut options = gif::DecodeOptions::new();
        options.set_color_output(gif::ColorOutput::RGBA);
        let mut decoder = options.read_info(fs::File::open(path).unwrap()).unwrap();
        let (width, height) = (usize::from(decoder.width()), usize::from(decoder.height()));
        let mut picture = vec![0; width * height * 4];
        let mut frames = 0;
        while let Some(frame) = decoder.read_next_frame().unwrap() {
            assert_eq!((frame.left, frame.top), (0, 0));
            if frames <= keep {
                for (shown, new) in picture
                    .chunks_exact_mut(4)
                    .zip(frame.buffer.chunks_exact(4))
                {
                    if new[3] != 0 {
                        shown.copy_from_slice(new);
                    }
                }
            }
            frames += 1;
        }
        Decoded {
            width,
            height,
            frames,
            picture,
        }
    }

    fn pixel(&self, x: usize, y: usize) -> [u8; 4] {
        let at = (y * self.width + x) * 4;
        self.picture[at..at + 4].try_into().unwrap()
    }
}

#[test]
fn a_run_becomes_one_frame_a_tick_with_the_robots_in_their_led_colours() {
    let dir = tempfile::tempdir().unwrap();
    tiny_run(dir.path(), false);
    let out = dir.path().join("run.gif");
    let report = write_gif(dir.path(), &out, &small()).unwrap();
    assert_eq!((report.frames, report.width, report.height), (4, 100, 50));
    assert_eq!(report.bytes, fs::metadata(&out).unwrap().len());

    let first = Decoded::read(&out, 0);
    assert_eq!((first.width, first.height, first.frames), (100, 50, 4));
    // Behind each robot's centre (its heading line points +x), in the first frame.
    assert_eq!(first.pixel(27, 15), [255, 0, 0, 255]);
    assert_eq!(first.pixel(67, 35), [0, 0, 255, 255]);
    assert_eq!(
        first.pixel(50, 5),
        [255, 255, 255, 255],
        "the arena is white"
    );

    let last = Decoded::read(&out, 3);
    assert_eq!(
        last.pixel(67, 38),
        colour_of([60, 60, 60]),
        "a dead robot is dark grey"
    );
    let [r, g, b, _] = render::PROGRESS;
    assert_eq!(
        last.pixel(99, 49),
        colour_of([r, g, b]),
        "the progress bar is full"
    );
    let leftovers: Vec<_> = fs::read_dir(dir.path())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "no temporary file is left");
}

fn colour_of(rgb: [u8; 3]) -> [u8; 4] {
    let [r, g, b] = palette::colour(palette::nearest(rgb));
    [r, g, b, 255]
}

#[test]
fn the_pheromone_field_is_drawn_under_the_robots() {
    let dir = tempfile::tempdir().unwrap();
    tiny_run(dir.path(), true);
    let out = dir.path().join("run.gif");
    write_gif(dir.path(), &out, &small()).unwrap();
    let first = Decoded::read(&out, 0);
    assert_eq!(first.pixel(10, 10), [255, 255, 255, 255], "an empty cell");
    // Green at 200/255 over white.
    assert_eq!(first.pixel(90, 10), colour_of([55, 255, 55]), "a full cell");
}

#[test]
fn ticks_and_size_follow_the_options() {
    let dir = tempfile::tempdir().unwrap();
    tiny_run(dir.path(), false);
    let out = dir.path().join("part.gif");
    let options = GifOptions {
        frames: 2,
        width_px: 40,
        from: Some(1),
        to: Some(3),
    };
    let report = write_gif(dir.path(), &out, &options).unwrap();
    assert_eq!((report.frames, report.width, report.height), (2, 40, 20));
    let beyond = GifOptions {
        to: Some(4),
        ..small()
    };
    let error = write_gif(dir.path(), &out, &beyond).unwrap_err();
    assert!(matches!(error, AnimationError::Options(_)), "{error}");
    assert!(
        error.to_string().contains("the run has ticks 0 to 3"),
        "{error}"
    );
    for bad in [
        GifOptions {
            frames: 0,
            ..small()
        },
        GifOptions {
            width_px: 5,
            ..small()
        },
    ] {
        assert!(matches!(
            write_gif(dir.path(), &out, &bad),
            Err(AnimationError::Options(_))
        ));
    }
}

#[test]
fn a_run_without_a_scene_says_it_predates_the_viewer() {
    let dir = tempfile::tempdir().unwrap();
    tiny_run(dir.path(), false);
    fs::remove_file(dir.path().join("scene.json")).unwrap();
    let out = dir.path().join("run.gif");
    let error = write_gif(dir.path(), &out, &small()).unwrap_err();
    assert!(matches!(error, AnimationError::NoScene(_)), "{error:?}");
    assert!(
        error.to_string().contains("scene.json is missing"),
        "{error}"
    );
    assert!(error.to_string().contains("before the viewer"), "{error}");
    assert!(!out.exists());
}

#[test]
fn a_run_without_ticks_or_folder_is_an_error_not_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    tiny_run(dir.path(), false);
    fs::write(
        dir.path().join("trajectory.csv"),
        "tick,robot,robot_id,x,y,heading,led_r,led_g,led_b,alive\n",
    )
    .unwrap();
    let out = dir.path().join("run.gif");
    let error = write_gif(dir.path(), &out, &small()).unwrap_err();
    assert!(matches!(error, AnimationError::NoTicks(_)), "{error:?}");
    assert!(error.to_string().contains("no complete tick"), "{error}");

    let missing = dir.path().join("nowhere");
    let error = write_gif(&missing, &out, &small()).unwrap_err();
    assert!(matches!(error, AnimationError::NotARun(_)), "{error:?}");

    tiny_run(dir.path(), false);
    let error = write_gif(dir.path(), &missing.join("run.gif"), &small()).unwrap_err();
    assert!(error.to_string().starts_with("cannot write "), "{error}");
}

#[test]
fn frames_spread_evenly_and_play_in_ten_to_twenty_seconds() {
    let frames = Frames {
        from: 0,
        to: 300,
        count: 200,
    };
    let ticks: Vec<u64> = (0..frames.count).map(|f| frames.tick(f)).collect();
    assert_eq!((ticks[0], ticks[199]), (0, 300));
    assert!(ticks.windows(2).all(|w| w[0] < w[1]));
    assert_eq!(frames.delay(20.0), 8, "15 s of run in 15 s");
    assert_eq!(frames.delay(300.0), 5, "1 s of run in 10 s");
    let long = Frames {
        from: 0,
        to: 36_000,
        count: 200,
    };
    assert_eq!(long.delay(10.0), 10, "an hour in 20 s");
    let many = Frames {
        count: 5_000,
        ..long
    };
    assert_eq!(many.delay(10.0), 2, "at most 50 frames a second");
    let one = Frames {
        from: 7,
        to: 7,
        count: 1,
    };
    assert_eq!((one.tick(0), one.progress(7)), (7, 1.0));
}

#[test]
fn the_report_reads_as_a_sentence() {
    let report = GifReport {
        path: "runs/f/run.gif".into(),
        frames: 200,
        width: 480,
        height: 480,
        bytes: 3_100_000,
        seconds: 2.4,
    };
    assert_eq!(
        report.to_string(),
        "runs/f/run.gif: 200 frames, 480 x 480, 3.1 MB in 2.4 s"
    );
}

/// `SWARM_GIF_RUN=/tmp/gif-run cargo test -p swarm-viewer -- --ignored --nocapture animation`: animates a real
/// run into `/tmp/gif-run.gif` and writes its middle frame to `/tmp/gif-frame.png`.
#[test]
#[ignore = "needs a recorded run in SWARM_GIF_RUN"]
fn a_recorded_run() {
    let run = std::env::var("SWARM_GIF_RUN").expect("SWARM_GIF_RUN names a run directory");
    let out = Path::new("/tmp/gif-run.gif");
    let report = write_gif(Path::new(&run), out, &GifOptions::default()).unwrap();
    println!("{report}");
    let middle = report.frames as usize / 2;
    let decoded = Decoded::read(out, middle);
    assert_eq!(decoded.frames, report.frames as usize);
    let file = fs::File::create("/tmp/gif-frame.png").unwrap();
    let mut encoder = png::Encoder::new(file, decoded.width as u32, decoded.height as u32);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().unwrap();
    writer.write_image_data(&decoded.picture).unwrap();
}
