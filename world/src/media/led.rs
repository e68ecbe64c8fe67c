//! The LED medium: every lit LED in the arena (robots, targets lying in the arena, lights) with a grid over their
//! positions for the cameras' range queries. A robot's LEDs are one source at its centre (a foot-bot's ring of 12
//! counts as one blob), plus its beacon if its body has one.

use swarm_contract::messages::Rgb;

use crate::entities::{Light, Robot, Target, TargetState};
use crate::geometry::{Aabb, Vec2};
use crate::scene::BodyRef;
use crate::spatial::Grid;

/// One lit LED.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LedSource {
    /// Position on the ground plane.
    pub position: Vec2,
    /// Height above the ground in metres.
    pub height: f32,
    /// Colour.
    pub color: Rgb,
    /// The body that carries it (never occludes its own LED); `None` for lights.
    pub owner: Option<BodyRef>,
}

/// The lit LEDs of one tick.
#[derive(Debug, Clone)]
pub struct LedMedium {
    /// The LEDs.
    pub leds: Vec<LedSource>,
    points: Vec<Aabb>,
    grid: Grid,
}

impl LedMedium {
    /// An empty medium over the arena rectangle `min..max`, with grid cells of side `cell`.
    pub fn new(min: Vec2, max: Vec2, cell: f32) -> Self {
        Self {
            leds: Vec::new(),
            points: Vec::new(),
            grid: Grid::new(min, max, cell),
        }
    }

    /// Refills the medium: alive robots with their LED on, targets in the arena, lights that are on.
    pub fn rebuild(&mut self, robots: &[Robot], targets: &[Target], lights: &[Light]) {
        self.leds.clear();
        for (i, r) in robots.iter().enumerate().filter(|(_, r)| r.alive) {
            let owner = Some(BodyRef::Robot(i as u32));
            if r.led.is_on() {
                self.leds.push(LedSource {
                    position: r.position,
                    height: r.body.led_height,
                    color: r.led,
                    owner,
                });
            }
            if let Some(height) = r.body.beacon_height.filter(|_| r.beacon.is_on()) {
                self.leds.push(LedSource {
                    position: r.position,
                    height,
                    color: r.beacon,
                    owner,
                });
            }
        }
        for (i, t) in targets
            .iter()
            .enumerate()
            .filter(|(_, t)| t.state == TargetState::InArena && t.led.is_on())
        {
            self.leds.push(LedSource {
                position: t.placed.position,
                height: t.led_height,
                color: t.led,
                owner: Some(BodyRef::Target(i as u32)),
            });
        }
        for l in lights.iter().filter(|l| l.color.is_on()) {
            self.leds.push(LedSource {
                position: l.position,
                height: l.height,
                color: l.color,
                owner: None,
            });
        }
        self.points.clear();
        self.points
            .extend(self.leds.iter().map(|l| Aabb::around(l.position, 0.0)));
        self.grid.rebuild(&self.points);
    }

    /// Calls `f` with every LED in the grid cells within `radius` of `centre` (each once; callers check the
    /// exact distance).
    pub fn near(&self, centre: Vec2, radius: f32, mut f: impl FnMut(&LedSource)) {
        self.grid
            .query(&Aabb::around(centre, radius), |i| f(&self.leds[i as usize]));
    }
}
