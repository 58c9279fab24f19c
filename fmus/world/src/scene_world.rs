//! The greenhouse held in a rapier world: every scene object a collider whose `user_data` is
//! its index in [`SceneWorld::objects`], every fruit its own rigid body (fixed for now, so
//! harvesting can later detach it and let it fall), the robot base a kinematic body.
//!
//! Only collision detection runs so far (rapier's `CollisionPipeline`: broad phase kept current,
//! no integration). The sets are the ones a `PhysicsPipeline` steps, so harvest physics can
//! switch fruit to dynamic bodies without rebuilding anything.

use crate::base_box::BaseBox;
use crate::geometry::{pose_of, shape_of};
use agrisim_greenhouse::scene::{Kind, Object};
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
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fruit {
    /// Index into [`SceneWorld::objects`].
    pub object: usize,
    pub body: RigidBodyHandle,
}

/// The robot base: a kinematic body with one box collider.
#[derive(Clone, Debug)]
pub struct Robot {
    pub body: RigidBodyHandle,
    pub collider: ColliderHandle,
    pub shape: SharedShape,
    pub base: BaseBox,
}

/// rapier's collision pipeline holds only scratch buffers: a copy of the world (an FMU state)
/// starts with fresh ones.
struct Scratch(CollisionPipeline);

impl Clone for Scratch {
    fn clone(&self) -> Self {
        Scratch(CollisionPipeline::new())
    }
}

#[derive(Clone)]
pub struct SceneWorld {
    pub bodies: RigidBodySet,
    pub colliders: ColliderSet,
    pub islands: IslandManager,
    pub broad_phase: BroadPhaseBvh,
    pub narrow_phase: NarrowPhase,
    pub params: IntegrationParameters,
    pub objects: Vec<SceneObject>,
    pub fruit: Vec<Fruit>,
    pub robot: Robot,
    scratch: Scratch,
}

impl SceneWorld {
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
                fruit.push(Fruit { object: index, body });
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
        let collider = colliders.insert_with_parent(ColliderBuilder::new(shape.clone()).user_data(ROBOT_TAG), body, &mut bodies);
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
            scratch: Scratch(CollisionPipeline::new()),
        };
        world.refresh();
        Ok(world)
    }

    /// Moves the robot base to `pose` (map frame) and brings collision detection up to date.
    /// (A teleport: once a `PhysicsPipeline` steps the world, `set_next_kinematic_position`
    /// gives pushed fruit the robot's velocity instead.)
    pub fn move_robot(&mut self, pose: Pose) {
        self.bodies[self.robot.body].set_position(pose, true);
        self.refresh();
    }

    /// Broad and narrow phase after bodies moved.
    fn refresh(&mut self) {
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
