//! Rigid-body physics: rapier2d with dynamic robot discs driven by velocity, fixed obstacles, movable objects.
//!
//! Robots are dynamic bodies whose velocity is set from the differential-drive model before every step, so the
//! solver resolves contacts (kinematic bodies would pass through walls). One rapier step per tick with
//! `dt = 1 / ticks_per_second`, zero gravity (the arena is seen from above). Contacts that start during a step are
//! collected per robot for the collision metrics. This module knows nothing about sensors or configuration.

use std::sync::Mutex;

use rapier2d::math::Pose;
use rapier2d::prelude::{
    ActiveEvents, ColliderBuilder, ColliderHandle, ColliderSet, CollisionEvent, ContactPair,
    EventHandler, FixedJointBuilder, ImpulseJointHandle, MassProperties, PhysicsWorld,
    RevoluteJointBuilder, RigidBodyBuilder, RigidBodyHandle, RigidBodySet, SoftBodySet,
    SoftBodyTearEvent,
};

use crate::geometry::{Shape, Vec2};

/// Ground friction of movable objects, as linear and angular damping per second: a pushed object stops soon.
pub const MOVABLE_DAMPING: f32 = 5.0;

/// Whether a body moves and how.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Motion {
    /// Never moves (walls, fixed obstacles, fixed targets).
    Fixed,
    /// Pushed by robots; the mass is in kg.
    Movable {
        /// Mass in kg.
        mass: f32,
    },
}

/// Collects the robot contacts that start during a step; preallocated so a step does not allocate.
struct ContactCollector {
    started: Mutex<Vec<(u128, u128)>>,
}

impl EventHandler for ContactCollector {
    fn handle_collision_event(
        &self,
        _bodies: &RigidBodySet,
        colliders: &ColliderSet,
        event: CollisionEvent,
        _contact_pair: Option<&ContactPair>,
    ) {
        if let CollisionEvent::Started(a, b, _) = event {
            let tag = |h: ColliderHandle| colliders.get(h).map_or(0, |c| c.user_data);
            if let Ok(mut started) = self.started.lock() {
                started.push((tag(a), tag(b)));
            }
        }
    }

    fn handle_contact_force_event(
        &self,
        _dt: f32,
        _bodies: &RigidBodySet,
        _colliders: &ColliderSet,
        _contact_pair: &ContactPair,
        _total_force_magnitude: f32,
    ) {
    }

    fn handle_soft_body_tear_event(&self, _soft_bodies: &SoftBodySet, _event: &SoftBodyTearEvent) {}
}

/// The physics state of the arena.
pub struct Physics {
    world: PhysicsWorld,
    collector: ContactCollector,
    started: Vec<(u128, u128)>,
}

/// Handles of one body in the physics world.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BodyHandles {
    /// The rigid body.
    pub body: RigidBodyHandle,
    /// Its one collider.
    pub collider: ColliderHandle,
}

impl Physics {
    /// An empty world stepping `dt` seconds per tick.
    pub fn new(dt: f32) -> Self {
        let mut world = PhysicsWorld {
            gravity: Vec2::ZERO,
            ..PhysicsWorld::default()
        };
        world.integration_parameters.dt = dt;
        Self {
            world,
            collector: ContactCollector {
                started: Mutex::new(Vec::with_capacity(1024)),
            },
            started: Vec::new(),
        }
    }

    /// Adds a body of `shape` at `position`/`angle`. `tag` is reported back with the contacts it starts;
    /// `report_contacts` turns that reporting on (robots).
    pub fn add(
        &mut self,
        shape: Shape,
        position: Vec2,
        angle: f32,
        motion: Motion,
        tag: u128,
        report_contacts: bool,
    ) -> BodyHandles {
        let builder = match motion {
            Motion::Fixed => RigidBodyBuilder::fixed(),
            Motion::Movable { .. } => RigidBodyBuilder::dynamic()
                .linear_damping(MOVABLE_DAMPING)
                .angular_damping(MOVABLE_DAMPING),
        };
        let body = builder
            .translation(position)
            .rotation(angle)
            .can_sleep(false)
            .build();
        let collider = match shape {
            Shape::Disc { radius } => ColliderBuilder::ball(radius),
            Shape::Rect { half } => ColliderBuilder::cuboid(half.x, half.y),
        };
        let mut collider = collider.friction(0.0).restitution(0.0).user_data(tag);
        if let Motion::Movable { mass } = motion {
            collider = collider.mass(mass);
        }
        if report_contacts {
            collider = collider.active_events(ActiveEvents::COLLISION_EVENTS);
        }
        let (body, collider) = self.world.insert(body, collider.build());
        BodyHandles { body, collider }
    }

    /// Adds a robot: a dynamic disc of `radius` and `mass` (kg) whose velocity the world sets every tick.
    pub fn add_robot(
        &mut self,
        radius: f32,
        mass: f32,
        position: Vec2,
        angle: f32,
        tag: u128,
    ) -> BodyHandles {
        let body = RigidBodyBuilder::dynamic()
            .translation(position)
            .rotation(angle)
            .can_sleep(false)
            .build();
        let collider = ColliderBuilder::ball(radius)
            .mass(mass)
            .friction(0.0)
            .restitution(0.0)
            .user_data(tag)
            .active_events(ActiveEvents::COLLISION_EVENTS)
            .build();
        let (body, collider) = self.world.insert(body, collider);
        BodyHandles { body, collider }
    }

    /// Adds rotational inertia to a robot's body (`extra` in kg m^2): its wheels then hold the base against
    /// reaction torques, such as its own turret turning a held object.
    pub fn hold_rotation(&mut self, body: RigidBodyHandle, extra: f32) {
        if let Some(b) = self.world.bodies.get_mut(body) {
            b.set_additional_mass_properties(MassProperties::new(Vec2::ZERO, 0.0, extra), true);
        }
    }

    /// Sets a robot's linear speed along its heading (m/s) and its turn rate (rad/s) for the next step.
    pub fn drive(&mut self, body: RigidBodyHandle, speed: f32, turn_rate: f32) {
        if let Some(b) = self.world.bodies.get_mut(body) {
            let heading = b.rotation().angle();
            b.set_linvel(crate::geometry::unit(heading) * speed, true);
            b.set_angvel(turn_rate, true);
        }
    }

    /// Enables or disables a body's collider (a carried target leaves the arena).
    pub fn set_enabled(&mut self, handles: BodyHandles, enabled: bool) {
        if let Some(c) = self.world.colliders.get_mut(handles.collider) {
            c.set_enabled(enabled);
        }
    }

    /// Moves a body to a new pose and stops it.
    pub fn teleport(&mut self, body: RigidBodyHandle, position: Vec2, angle: f32) {
        if let Some(b) = self.world.bodies.get_mut(body) {
            b.set_translation(position, true);
            b.set_rotation(rapier2d::math::Rotation::new(angle), true);
            b.set_linvel(Vec2::ZERO, true);
            b.set_angvel(0.0, true);
        }
    }

    /// Pins `body1` and `body2` together at the arena point `at` with a revolute joint (the bodies may turn about
    /// it, as a gripper's pivot lets them); the pinned bodies no longer collide with each other.
    pub fn pin(
        &mut self,
        body1: RigidBodyHandle,
        body2: RigidBodyHandle,
        at: Vec2,
    ) -> Option<ImpulseJointHandle> {
        let (anchor1, anchor2) = (self.local_point(body1, at)?, self.local_point(body2, at)?);
        let joint = RevoluteJointBuilder::new()
            .local_anchor1(anchor1)
            .local_anchor2(anchor2)
            .contacts_enabled(false)
            .build();
        Some(self.world.impulse_joints.insert(body1, body2, joint, true))
    }

    /// Welds `body2` to `body1` as they are now, at the frame `(anchor, angle)` of `body1` (a gripper's point and
    /// direction): the second body then moves and turns with that frame.
    pub fn weld(
        &mut self,
        body1: RigidBodyHandle,
        body2: RigidBodyHandle,
        anchor: Vec2,
        angle: f32,
    ) -> Option<ImpulseJointHandle> {
        let pose = |h: RigidBodyHandle| self.world.bodies.get(h).map(|b| *b.position());
        let (pose1, pose2) = (pose(body1)?, pose(body2)?);
        let frame1 = Pose::new(anchor, angle);
        let frame2 = pose2.inverse() * pose1 * frame1;
        let joint = FixedJointBuilder::new()
            .local_frame1(frame1)
            .local_frame2(frame2)
            .contacts_enabled(false)
            .build();
        Some(self.world.impulse_joints.insert(body1, body2, joint, true))
    }

    /// Moves a weld's frame on its first body to `(anchor, angle)`: the solver carries the second body along (a
    /// turret turning a held object).
    pub fn move_weld(&mut self, joint: ImpulseJointHandle, anchor: Vec2, angle: f32) {
        if let Some(j) = self.world.impulse_joints.get_mut(joint, true) {
            j.data.set_local_frame1(Pose::new(anchor, angle));
        }
    }

    /// Where `local` (a point in `body`'s frame) is in the arena now.
    pub fn point_on(&self, body: RigidBodyHandle, local: Vec2) -> Option<Vec2> {
        let b = self.world.bodies.get(body)?;
        Some(b.position().transform_point(local))
    }

    /// Where the arena point `at` lies in `body`'s frame now.
    pub fn local_point(&self, body: RigidBodyHandle, at: Vec2) -> Option<Vec2> {
        let b = self.world.bodies.get(body)?;
        Some(b.position().inverse_transform_point(at))
    }

    /// Removes a joint made by [`Physics::pin`] or [`Physics::weld`].
    pub fn unpin(&mut self, joint: ImpulseJointHandle) {
        self.world.impulse_joints.remove(joint, true);
    }

    /// Sets a movable body's ground friction, as linear and angular damping per second.
    pub fn set_damping(&mut self, body: RigidBodyHandle, damping: f32) {
        if let Some(b) = self.world.bodies.get_mut(body) {
            b.set_linear_damping(damping);
            b.set_angular_damping(damping);
        }
    }

    /// A body's linear velocity in m/s after the last step.
    pub fn velocity(&self, body: RigidBodyHandle) -> Vec2 {
        self.world
            .bodies
            .get(body)
            .map_or(Vec2::ZERO, |b| b.linvel())
    }

    /// Current position and heading of a body.
    pub fn pose(&self, body: RigidBodyHandle) -> (Vec2, f32) {
        self.world.bodies.get(body).map_or((Vec2::ZERO, 0.0), |b| {
            (b.translation(), b.rotation().angle())
        })
    }

    /// Advances one tick and returns the pairs of tags whose contact started during it.
    pub fn step(&mut self) -> &[(u128, u128)] {
        self.world.step_with_events(&(), &self.collector);
        self.started.clear();
        if let Ok(mut started) = self.collector.started.lock() {
            self.started.extend_from_slice(&started);
            started.clear();
        }
        &self.started
    }
}
