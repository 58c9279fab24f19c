//! The greenhouse held in a rapier world: every scene object a collider whose `user_data` is
//! its index in [`SceneWorld::objects`], every fruit its own rigid body (fixed while on its
//! plant; kinematic while held or placed; dynamic while falling), the robot base and links
//! kinematic bodies.
//!
//! While nothing is dynamic a step only teleports the kinematic bodies and runs rapier's
//! `CollisionPipeline` (broad phase kept current, no integration): the navigation case stays
//! as cheap as before the arms existed. While a released fruit falls, the step runs the
//! `PhysicsPipeline` in substeps of at most `max_dt`, the kinematic bodies interpolated
//! across them so what they push gets their velocity.

use crate::base_box::BaseBox;
use crate::geometry::{pose_of, shape_of};
use crate::robot_parts::{LinkBody, RobotPart};
use agrisim_scene::scene::{Kind, Object};
use rapier3d::prelude::*;

/// `user_data` of the robot's colliders (scene objects carry their index, far below this).
pub const ROBOT_TAG: u128 = u128::MAX;

/// What contact reports and ground truth need to know of a scene object.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneObject {
    pub id: u32,
    pub name: String,
    pub kind: Kind,
    pub collider: ColliderHandle,
}

/// A fruit's rigid body, in the order of the fruit list (`target_fruit` indexes it).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Fruit {
    /// Index into [`SceneWorld::objects`].
    pub object: usize,
    pub body: RigidBodyHandle,
    pub radius: f64,
}

/// Tomato density [kg/m^3] (about water's): a falling fruit's mass for rapier.
pub const FRUIT_DENSITY: f32 = 1000.0;

/// Standard gravity [m/s^2].
pub const GRAVITY: f32 = 9.81;

/// The robot base: a kinematic body with one box collider.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Robot {
    pub body: RigidBodyHandle,
    pub collider: ColliderHandle,
    pub shape: SharedShape,
    pub base: BaseBox,
}

/// rapier's pipelines hold only scratch buffers and caches: a copy of the world (an FMU
/// state) starts with fresh ones.
struct Scratch(CollisionPipeline, PhysicsPipeline);

impl Default for Scratch {
    fn default() -> Self {
        Scratch(CollisionPipeline::new(), PhysicsPipeline::new())
    }
}

impl Clone for Scratch {
    fn clone(&self) -> Self {
        Scratch(CollisionPipeline::new(), PhysicsPipeline::new())
    }
}

/// Serialized (an FMU state) without what the scene's parameters fix: the scene objects'
/// names and kinds and the robot parts ([`SceneWorld::adopt`] takes them over).
#[derive(Clone, serde::Serialize, serde::Deserialize)]
pub struct SceneWorld {
    pub bodies: RigidBodySet,
    pub colliders: ColliderSet,
    pub islands: IslandManager,
    pub broad_phase: BroadPhaseBvh,
    pub narrow_phase: NarrowPhase,
    pub params: IntegrationParameters,
    #[serde(skip)]
    pub objects: Vec<SceneObject>,
    pub fruit: Vec<Fruit>,
    pub robot: Robot,
    /// The URDF links (empty until [`SceneWorld::add_robot_links`]).
    pub links: Vec<LinkBody>,
    /// Every robot collider: part 0 is the base box, then the link primitives.
    #[serde(skip)]
    pub parts: Vec<RobotPart>,
    impulse_joints: ImpulseJointSet,
    multibody_joints: MultibodyJointSet,
    soft_bodies: SoftBodySet,
    ccd: CCDSolver,
    #[serde(skip)]
    scratch: Scratch,
}

impl SceneWorld {
    /// Becomes `loaded` (a deserialized world of the same scene), keeping this world's scene
    /// objects and robot parts, which serialization leaves out.
    pub fn adopt(&mut self, mut loaded: SceneWorld) {
        loaded.objects = std::mem::take(&mut self.objects);
        loaded.parts = std::mem::take(&mut self.parts);
        *self = loaded;
    }

    /// Builds the world from the scene's objects (in their order) and the robot base at `robot_pose`.
    pub fn build(objects: &[Object], base: BaseBox, robot_pose: Pose) -> Result<SceneWorld, String> {
        let mut bodies = RigidBodySet::new();
        let mut colliders = ColliderSet::new();
        let mut table = Vec::with_capacity(objects.len());
        let mut fruit = Vec::new();
        for (index, o) in objects.iter().enumerate() {
            let describe = |e: String| format!("scene object {} ({}): {e}", o.id, o.name);
            let pose = pose_of(&o.placement).map_err(describe)?;
            let (shape, offset) = shape_of(&o.shape).map_err(describe)?;
            let builder = ColliderBuilder::new(shape).user_data(index as u128);
            let collider = if matches!(o.kind, Kind::Fruit { .. }) {
                let body = bodies.insert(RigidBodyBuilder::fixed().pose(pose).user_data(o.id as u128));
                let radius = match o.shape {
                    agrisim_scene::scene::Shape::Sphere { radius } => radius,
                    _ => return Err(describe("a fruit must be a sphere".into())),
                };
                fruit.push(Fruit { object: index, body, radius });
                let builder = builder.density(FRUIT_DENSITY).friction(0.7).restitution(0.2);
                colliders.insert_with_parent(builder.position(offset), body, &mut bodies)
            } else {
                // Static structure: colliders without a body are fixed for rapier, and cost
                // no rigid body each (a 160-row house has ~10^5 of them).
                colliders.insert(builder.position(pose * offset))
            };
            table.push(SceneObject { id: o.id, name: o.name.clone(), kind: o.kind, collider });
        }
        if !robot_pose.is_finite() {
            return Err(format!("robot pose {robot_pose:?} is not finite"));
        }
        let shape = base.shape();
        let body = bodies.insert(RigidBodyBuilder::kinematic_position_based().pose(robot_pose));
        let collider =
            colliders.insert_with_parent(ColliderBuilder::new(shape.clone()).user_data(ROBOT_TAG), body, &mut bodies);
        let mut world = SceneWorld {
            bodies,
            colliders,
            islands: IslandManager::new(),
            broad_phase: BroadPhaseBvh::new(),
            narrow_phase: NarrowPhase::new(),
            params: IntegrationParameters::default(),
            objects: table,
            fruit,
            robot: Robot { body, collider, shape, base },
            links: Vec::new(),
            parts: Vec::new(),
            impulse_joints: ImpulseJointSet::new(),
            multibody_joints: MultibodyJointSet::new(),
            soft_bodies: SoftBodySet::default(),
            ccd: CCDSolver::new(),
            scratch: Scratch(CollisionPipeline::new(), PhysicsPipeline::new()),
        };
        world.refresh();
        Ok(world)
    }

    /// Puts kinematic bodies at their new poses for the end of a step of `h` seconds. With
    /// `dynamic` (something falls) the physics runs in `ceil(h / max_dt)` substeps under
    /// gravity, the kinematic bodies moving linearly across them; otherwise they teleport.
    /// `awake` lists further kinematic bodies falling things may land on (carried and placed
    /// fruit): rapier's solver only sees kinematic bodies that are awake.
    pub fn advance(
        &mut self,
        moves: &[(RigidBodyHandle, Pose)],
        awake: &[RigidBodyHandle],
        h: f64,
        dynamic: bool,
        max_dt: f64,
    ) {
        if !dynamic {
            for &(body, pose) in moves {
                self.bodies[body].set_position(pose, true);
            }
            self.refresh();
            return;
        }
        let n = (h / max_dt).ceil().clamp(1.0, 10_000.0) as usize;
        let start: Vec<Pose> = moves.iter().map(|&(b, _)| *self.bodies[b].position()).collect();
        let mut params = self.params;
        params.dt = (h / n as f64) as Real;
        for k in 1..=n {
            let s = k as Real / n as Real;
            for (&(body, to), from) in moves.iter().zip(&start) {
                let pose = if k == n { to } else { from.lerp(&to, s) };
                self.bodies[body].set_next_kinematic_position(pose);
            }
            // rapier's solver only sees kinematic bodies that are awake: a resting robot
            // part would let falling fruit pass through it.
            self.bodies[self.robot.body].wake_up(true);
            for link in &self.links {
                self.bodies[link.body].wake_up(true);
            }
            for &body in awake {
                self.bodies[body].wake_up(true);
            }
            self.scratch.1.step(
                Vector::new(0.0, 0.0, -GRAVITY),
                &params,
                &mut self.islands,
                &mut self.broad_phase,
                &mut self.narrow_phase,
                &mut self.bodies,
                &mut self.colliders,
                &mut self.impulse_joints,
                &mut self.multibody_joints,
                &mut self.soft_bodies,
                &mut self.ccd,
                &(),
                &(),
            );
        }
    }

    /// Index into the fruit list of scene object `object`, if it is a fruit.
    pub fn fruit_of_object(&self, object: usize) -> Option<usize> {
        self.fruit.binary_search_by_key(&object, |f| f.object).ok()
    }

    /// Broad and narrow phase after bodies or colliders moved.
    pub fn refresh(&mut self) {
        self.scratch.0.step(
            self.params.prediction_distance(),
            &mut self.islands,
            &mut self.broad_phase,
            &mut self.narrow_phase,
            &mut self.bodies,
            &mut self.colliders,
            &(),
            &(),
        );
    }

    pub fn robot_pose(&self) -> Pose {
        *self.colliders[self.robot.collider].position()
    }

    /// Scene queries over everything but the robot.
    pub fn query_pipeline(&self) -> QueryPipeline<'_> {
        self.broad_phase.as_query_pipeline(
            self.narrow_phase.query_dispatcher(),
            &self.bodies,
            &self.colliders,
            QueryFilter::default().exclude_rigid_body(self.robot.body),
        )
    }

    /// The scene object a collider stands for (None for the robot's own colliders).
    pub fn object_of(&self, collider: &Collider) -> Option<usize> {
        let index = collider.user_data;
        (index != ROBOT_TAG && index < self.objects.len() as u128).then_some(index as usize)
    }

    /// Current pose of fruit `i` of the fruit list (its body's pose: fruit will move).
    pub fn fruit_pose(&self, i: usize) -> Pose {
        *self.bodies[self.fruit[i].body].position()
    }
}

/// Objects the robot's contact and clearance reports ignore: the floor it drives on.
pub fn is_ground(kind: Kind) -> bool {
    kind == Kind::Floor
}
