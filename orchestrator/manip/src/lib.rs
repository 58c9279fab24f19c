//! Manipulation planning core of agrisim's dual-arm harvest: arm kinematics from the robot
//! URDF, inverse kinematics, sphere-model and exact (parry3d) collision checking, RRT-Connect
//! to a goal set and shortcutting. Time parameterization lives in `agrisim-trajectory`.
//!
//! Planning frame: `base_link`. Both arms sit on the lift, whose height is an input (`lift`,
//! m) of every query; the IK can also free it as an 8th joint. Everything is deterministic:
//! randomness comes only from the caller's seeded [`Rng`], budgets are iteration counts, and
//! wall time appears only in statistics.
//!
//! # API
//! ```text
//! // Kinematics (chain)
//! ArmModel::new(side: Side) -> ArmModel                       // cached per side; Clone
//! arm.fk(lift, &q) -> agrisim_robot::Pose                      // TCP `{side}_hand_tcp`
//! arm.fk_iso(lift, &q) -> Isometry3<f64>
//! arm.frames(lift, &q, finger) -> Frames { bodies: [Isometry3; 11], tcp, .. }   // + .jacobian() 6x8
//! arm.jacobian(lift, &q) -> Matrix6xX<f64>                     // 6x7 geometric, [v; w]
//! arm.limits: [Limits; 7], arm.lower(), arm.upper(), arm.within_limits(&q), arm.random_q(&mut rng)
//! arm.joint_names: [String; 7]
//!
//! // IK (ik, target, kdl)
//! Target::pose(iso) | Target::free_roll(iso) | Target::from_pose(&Pose, free_roll)  // tol 1 mm, 0.01 rad
//! Ik::new(&arm, lift) | Ik::with_free_lift(&arm, lift_start)
//! ik.solve(&target, &seed_q, &mut rng, budget) -> Option<[f64; 7]>    // budget: ik::DEFAULT_BUDGET
//! ik.solve_lift(&target, &seed_q, &mut rng, budget) -> Option<(lift, [f64; 7])>
//! ik.goal_set(&target, &seed_q, &mut rng, n, min_dist, budget, |q| valid) -> Vec<[f64; 7]>
//! kdl::kdl_nr_jl(&arm, lift, &target, &seed) -> Option<[f64; 7]>  // baseline only
//!
//! // Scene and collision (scene, checker, exact)
//! Obstacle::new(name, agrisim_robot::Shape, pose: Isometry3, ObstacleKind::{Solid, Soft, Target})
//! Scene::new(Vec<Obstacle>), Scene::empty()
//! Context::new(&arm, lift, &scene).with_other(&other_arm, other_q, other_finger)
//!     .holding(fruit_radius).other_holding(fruit_radius)   // optional held fruits at the TCPs
//!     // pub fields: finger (this arm's opening, default open), padding (default 0.01 m), held
//! // Contact { body: index into layout::BODY_NAMES or checker::HELD, hit: Hit::{SelfBody, RobotBody, OtherArm, Object} }
//! Checker::new(ctx): .is_valid(&q), .contact(&q) -> Option<Contact>, .edge_valid(&a, &b, res)
//! exact::exact_check(&ctx, &path, exact::EXACT_RESOLUTION) -> Result<(), PathContact>
//! exact::exact_contact(&ctx, &q) -> Option<Contact>
//!
//! // Planning (planner, rrt_connect, shortcut)
//! Planner::default() / Planner::new(PlannerConfig { rrt: RrtConfig, shortcut_iterations, exact_check, exact_resolution })
//! planner.plan(&ctx, &start, &goals, &mut rng) -> Result<Plan, PlanError>
//! Plan { waypoints: Vec<[f64; 7]>, goal_index, stats: PlanStats }
//! cartesian_path(&checker, &start, offset_planning_frame, step_m, max_jump_rad, resolution)
//!     -> Result<Vec<[f64; 7]>, CartesianError { fraction, reason, partial }>   // approach/retreat
//! ```
//! Typical use for one harvest motion: build a `Scene` from the perceived/world objects
//! (leaves `Soft`, the fruit `Target`), a `Context` for the moving arm with the other arm's
//! current state, `Ik::goal_set` of a `Target::free_roll` at the pre-grasp pose filtered by
//! `Checker::is_valid`, then `Planner::plan` from the current joints to that goal set.

pub mod acm;
pub mod body;
pub mod cartesian;
pub mod chain;
pub mod checker;
pub mod exact;
pub mod ik;
pub mod iso;
pub mod kdl;
pub mod layout;
pub mod meter;
pub mod planner;
pub mod prim;
pub mod rrt_connect;
pub mod scene;
pub mod shortcut;
pub mod spheres;
pub mod target;

pub use agrisim_math::Rng;
pub use agrisim_robot::{Pose, Shape};
pub use cartesian::{cartesian_path, CartesianError};
pub use chain::{ArmModel, Side};
pub use checker::{Checker, Contact, Context, Held, Hit};
pub use exact::{exact_check, PathContact};
pub use ik::Ik;
pub use layout::DOF;
pub use meter::{CostModel, Meter, Work};
pub use planner::{Plan, PlanError, PlanStats, Planner, PlannerConfig};
pub use scene::{Obstacle, ObstacleKind, Scene};
pub use target::Target;
