//! The Greenhouse FMU's variable table: scene parameters, the robot pose coming in from the
//! other FMUs, contact and clearance outputs, and ground-truth fruit poses. The scene
//! parameters, the base box and the base pose inputs are the sensor FMUs' declarations
//! (`agrisim_sensor_ports`), so every FMU reads the same scene and base box from
//! the same scenario keys with the same defaults and ranges; only descriptions are the world's.

use agrisim_fmi::{Start, Var};
use agrisim_sensor_ports as sensor_ports;

/// MIME types of the message ports (FMI 3 Binary variables carrying ROS 2 CDR).
pub const COLLISION_STATE_MIME: &str = "application/x-ros2-cdr-frames; version=1; type=agrisim_msgs/msg/CollisionState";
pub const POSE_ARRAY_MIME: &str = "application/x-ros2-cdr-frames; version=1; type=geometry_msgs/msg/PoseArray";
pub const POSE_STAMPED_MIME: &str = "application/x-ros2-cdr-frames; version=1; type=geometry_msgs/msg/PoseStamped";
pub const PLANNING_SCENE_MIME: &str = "application/x-ros2-cdr-frames; version=1; type=agrisim_msgs/msg/PlanningScene";
pub const PLANT_DAMAGE_MIME: &str = "application/x-ros2-cdr-frames; version=1; type=agrisim_msgs/msg/PlantDamage";
pub use agrisim_sensor_ports::MOVED_OBJECTS_MIME;

agrisim_fmi::variables! { pub VARIABLES {
    // --- scene (fixed parameters) ---
    SCENE = sensor_ports::SCENE,
    SEED = sensor_ports::SCENE_SEED
        .desc("Seed of the greenhouse generator (plants, fruit, random obstacles); < 0 = the scene's own seed key"),
    // --- robot base box (fixed parameters) ---
    BASE_LENGTH = sensor_ports::BASE_BOX[0],
    BASE_WIDTH = sensor_ports::BASE_BOX[1].desc("Robot base box extent along base_link y"),
    BASE_HEIGHT = sensor_ports::BASE_BOX[2].desc("Robot base box extent along z"),
    BASE_CLEARANCE = sensor_ports::BASE_BOX[3]
        .desc("Height of the box bottom above the floor; the box spans the navigation height band"),
    CLEARANCE_CAP = Var::param("clearance_cap", Start::Float64(5.0)).unit("m").range(0.01, 1000.0)
        .desc("min_clearance reports at most this distance (nothing nearer than the cap)"),
    // --- publication rates (fixed parameters) ---
    COLLISION_RATE = Var::param("collision_rate", Start::Float64(10.0)).unit("Hz").range(0.001, 1e6)
        .desc("Publication rate of collision_state (it is also published at once when the contact set changes)"),
    FRUIT_RATE = Var::param("fruit_rate", Start::Float64(1.0)).unit("Hz").range(0.001, 1e6)
        .desc("Publication rate of fruit_poses and target"),
    // --- inputs: robot pose (ground truth of the chassis and lift FMUs) ---
    BASE_X = sensor_ports::BASE_POSE[0],
    BASE_Y = sensor_ports::BASE_POSE[1],
    BASE_YAW = sensor_ports::BASE_POSE[2],
    LIFT_POSITION = sensor_ports::robot::LIFT_POSITION,
    TARGET_FRUIT = Var::input_discrete("target_fruit", Start::Int32(-1))
        .desc("Index into the fruit list (order of fruit_poses) whose pose is the target; -1 = none"),
    // --- outputs: contacts and clearance (at initialization: of the robot as the inputs
    // place it; every message is published once, so the *_seq counters start at 1 except
    // target's, which needs a valid target_fruit; nothing is held, picked or placed yet) ---
    COLLISION = Var::output_discrete("collision", Start::Boolean(false)).init_depends_on(&CONTACTS)
        .desc("Any robot contact now: a scene object (floor excluded for the base box; carried, falling and placed fruit excluded), arm vs arm, or a carried fruit vs the structure"),
    COLLISION_COUNT = Var::output_discrete("collision_count", Start::Int32(0)).init_depends_on(&CONTACTS)
        .desc("Cumulative contact onsets, all categories (sum of contact_robot_plant, contact_robot_structure, contact_arm_arm, contact_carried_structure)"),
    MIN_CLEARANCE = Var::output("min_clearance").unit("m").init_depends_on(&[SCENE, SEED, BASE_LENGTH, BASE_WIDTH, BASE_HEIGHT, BASE_CLEARANCE, BASE_X, BASE_Y, BASE_YAW, CLEARANCE_CAP])
        .desc("Distance from the base box to the nearest scene object within the base's height band, capped at clearance_cap"),
    COLLISION_STATE = Var::output_discrete("collision_state", Start::Binary(&[])).mime(COLLISION_STATE_MIME).init_depends_on(&COLLISION_REPORT)
        .desc("agrisim_msgs/CollisionState in the map frame, at collision_rate and whenever the contact set changes"),
    COLLISION_STATE_SEQ = Var::output_discrete("collision_state_seq", Start::Int64(0)).init_depends_on(&[])
        .desc("Sequence number of the newest message in collision_state"),
    // --- outputs: ground truth ---
    FRUIT_COUNT = Var::output_discrete("fruit_count", Start::Int32(0)).init_depends_on(&[SCENE, SEED]).desc("Number of fruit in the scene"),
    FRUIT_POSES = Var::output_discrete("fruit_poses", Start::Binary(&[])).mime(POSE_ARRAY_MIME).init_depends_on(&[SCENE, SEED, FRUIT_RATE, Var::TIME])
        .desc("geometry_msgs/PoseArray of every fruit centre (frame map), at fruit_rate"),
    FRUIT_POSES_SEQ = Var::output_discrete("fruit_poses_seq", Start::Int64(0)).init_depends_on(&[]).desc("Sequence number of the newest message in fruit_poses"),
    TARGET_VALID = Var::output_discrete("target_valid", Start::Boolean(false)).init_depends_on(TARGET_CHOICE)
        .desc("target_fruit names an existing fruit"),
    TARGET_ID = Var::output_discrete("target_id", Start::Int32(-1)).init_depends_on(TARGET_CHOICE)
        .desc("Scene object id of the target fruit (as in collision_state), -1 when none"),
    TARGET_X = Var::output("target_x").unit("m").init_depends_on(TARGET_CHOICE).desc("Target fruit centre in the map frame (0 when none)"),
    TARGET_Y = Var::output("target_y").unit("m").init_depends_on(TARGET_CHOICE),
    TARGET_Z = Var::output("target_z").unit("m").init_depends_on(TARGET_CHOICE),
    TARGET = Var::output_discrete("target", Start::Binary(&[])).mime(POSE_STAMPED_MIME).max_size(agrisim_fmi::port::frames_max_size(1024, 1024)).init_depends_on(&[SCENE, SEED, TARGET_FRUIT, Var::TIME])
        .desc("geometry_msgs/PoseStamped of the target fruit (frame map), at fruit_rate and when target_fruit changes"),
    TARGET_SEQ = Var::output_discrete("target_seq", Start::Int64(0)).init_depends_on(TARGET_CHOICE).desc("Sequence number of the newest message in target"),
    // --- harvest physics (appended: earlier value references stay as they were) ---
    LEFT_Q1 = sensor_ports::robot::ARM_JOINTS[0][0],
    LEFT_Q2 = sensor_ports::robot::ARM_JOINTS[0][1],
    LEFT_Q3 = sensor_ports::robot::ARM_JOINTS[0][2],
    LEFT_Q4 = sensor_ports::robot::ARM_JOINTS[0][3],
    LEFT_Q5 = sensor_ports::robot::ARM_JOINTS[0][4],
    LEFT_Q6 = sensor_ports::robot::ARM_JOINTS[0][5],
    LEFT_Q7 = sensor_ports::robot::ARM_JOINTS[0][6],
    RIGHT_Q1 = sensor_ports::robot::ARM_JOINTS[1][0],
    RIGHT_Q2 = sensor_ports::robot::ARM_JOINTS[1][1],
    RIGHT_Q3 = sensor_ports::robot::ARM_JOINTS[1][2],
    RIGHT_Q4 = sensor_ports::robot::ARM_JOINTS[1][3],
    RIGHT_Q5 = sensor_ports::robot::ARM_JOINTS[1][4],
    RIGHT_Q6 = sensor_ports::robot::ARM_JOINTS[1][5],
    RIGHT_Q7 = sensor_ports::robot::ARM_JOINTS[1][6],
    LEFT_FINGER_WIDTH = sensor_ports::robot::FINGER_WIDTHS[0],
    RIGHT_FINGER_WIDTH = sensor_ports::robot::FINGER_WIDTHS[1],
    GRASP_TOLERANCE = Var::param("grasp_tolerance", Start::Float64(0.003)).unit("m").range(0.0, 0.05)
        .desc("Attach: gap <= fruit diameter + this, and the fruit centre within the finger pads widened by this"),
    RELEASE_MARGIN = Var::param("release_margin", Start::Float64(0.005)).unit("m").range(0.0, 0.05)
        .desc("Release: gap > fruit diameter + this"),
    PHYSICS_DT = Var::param("physics_dt", Start::Float64(0.005)).unit("s").range(1e-4, 0.1)
        .desc("Largest rapier substep while a released fruit falls"),
    LEFT_GRASP_WIDTH = Var::output("left_grasp_width").unit("m").init_depends_on(&[])
        .desc("Diameter of the fruit between the left fingers (where the gripper stalls), 0 when empty"),
    RIGHT_GRASP_WIDTH = Var::output("right_grasp_width").unit("m").init_depends_on(&[])
        .desc("Diameter of the fruit between the right fingers, 0 when empty"),
    LEFT_HELD_ID = Var::output_discrete("left_held_id", Start::Int32(-1)).init_depends_on(&[])
        .desc("Scene object id of the fruit the left gripper holds (as target_id), -1 when none"),
    RIGHT_HELD_ID = Var::output_discrete("right_held_id", Start::Int32(-1)).init_depends_on(&[])
        .desc("Scene object id of the fruit the right gripper holds, -1 when none"),
    PICKED_COUNT = Var::output_discrete("picked_count", Start::Int32(0)).init_depends_on(&[])
        .desc("Fruit detached from their plants by a grasp (cumulative)"),
    PLACED_COUNT = Var::output_discrete("placed_count", Start::Int32(0)).init_depends_on(&[])
        .desc("Released fruit that came to rest inside the harvest box (cumulative)"),
    DROPPED_COUNT = Var::output_discrete("dropped_count", Start::Int32(0)).init_depends_on(&[])
        .desc("Releases that ended on the floor or at rest outside the box (cumulative)"),
    LAST_PLACED_ID = Var::output_discrete("last_placed_id", Start::Int32(-1)).init_depends_on(&[])
        .desc("Scene object id of the fruit placed last, -1 before the first"),
    CONTACT_ROBOT_PLANT = Var::output_discrete("contact_robot_plant", Start::Int32(0)).init_depends_on(&CONTACTS)
        .desc("Cumulative onsets of robot contact with stems, leaves, trusses, fruit on the crop (expected; not a failure)"),
    CONTACT_ROBOT_STRUCTURE = Var::output_discrete("contact_robot_structure", Start::Int32(0)).init_depends_on(&CONTACTS)
        .desc("Cumulative onsets of robot contact with posts, pipes, gutters, walls, obstacles, floor (a collision failure)"),
    CONTACT_ARM_ARM = Var::output_discrete("contact_arm_arm", Start::Int32(0)).init_depends_on(&CONTACTS)
        .desc("Cumulative onsets of left-arm vs right-arm link contact (a collision failure)"),
    PLANNING_SCENE_RADIUS = Var::param("planning_scene_radius", Start::Float64(2.5)).unit("m").range(0.0, 1000.0)
        .desc("planning_scene lists the objects whose bounding box comes this close (horizontally) to base_link"),
    PLANNING_SCENE_RATE = Var::param("planning_scene_rate", Start::Float64(1.0)).unit("Hz").range(0.001, 1e6)
        .desc("Publication rate of planning_scene"),
    PLANNING_SCENE = Var::output_discrete("planning_scene", Start::Binary(&[])).mime(PLANNING_SCENE_MIME).init_depends_on(&[SCENE, SEED, BASE_X, BASE_Y, PLANNING_SCENE_RADIUS, PLANNING_SCENE_RATE, Var::TIME])
        .desc("agrisim_msgs/PlanningScene: scene objects near the robot as primitives (frame map; ids = scene object ids), at planning_scene_rate"),
    PLANNING_SCENE_SEQ = Var::output_discrete("planning_scene_seq", Start::Int64(0)).init_depends_on(&[]).desc("Sequence number of the newest message in planning_scene"),
    PORT_WINDOW = agrisim_fmi::port_window(),
    // --- appended: earlier value references stay as they were ---
    CONTACT_CARRIED_STRUCTURE = Var::output_discrete("contact_carried_structure", Start::Int32(0)).init_depends_on(&CONTACTS)
        .desc("Cumulative onsets of a fruit held by a gripper touching posts, pipes, gutters, walls, obstacles, floor (the load swung into the structure)"),
    // --- plant physics (appended: earlier value references stay as they were; figures and
    // sources in crate::pedicel and crate::harvest::DamageParams) ---
    PEDICEL_ENABLED = Var::param("pedicel_enabled", Start::Boolean(true))
        .desc("A grasped fruit stays on its plant until its pedicel breaks (false: picked when the fingers close)"),
    PEDICEL_PULL_MEAN = Var::param("pedicel_pull_mean", Start::Float64(20.0)).unit("N").range(0.01, 1000.0)
        .desc("Mean tension at which a pedicel breaks at its abscission zone (Weng et al. 2024, Agronomy 14:2274)"),
    PEDICEL_PULL_SD = Var::param("pedicel_pull_sd", Start::Float64(5.0)).unit("N").range(0.0, 1000.0)
        .desc("Standard deviation of the per-fruit pull threshold (truncated at 20 % of the mean)"),
    PEDICEL_BEND_MEAN = Var::param("pedicel_bend_mean", Start::Float64(0.15)).unit("N.m").range(1e-4, 100.0)
        .desc("Mean bending moment at the abscission zone that breaks a pedicel (bending detaches with less force than pulling: Li et al. 2008)"),
    PEDICEL_BEND_SD = Var::param("pedicel_bend_sd", Start::Float64(0.04)).unit("N.m").range(0.0, 100.0)
        .desc("Standard deviation of the per-fruit bend threshold"),
    PEDICEL_TWIST_MEAN = Var::param("pedicel_twist_mean", Start::Float64(0.10)).unit("N.m").range(1e-4, 100.0)
        .desc("Mean twisting moment that breaks a pedicel (estimate)"),
    PEDICEL_TWIST_SD = Var::param("pedicel_twist_sd", Start::Float64(0.03)).unit("N.m").range(0.0, 100.0)
        .desc("Standard deviation of the per-fruit twist threshold"),
    PEDICEL_STIFFNESS = Var::param("pedicel_stiffness", Start::Float64(500.0)).unit("N/m").range(1.0, 1e6)
        .desc("Translational stiffness of the fruit on its truss at the abscission zone (estimate)"),
    PEDICEL_DAMPING = Var::param("pedicel_damping", Start::Float64(2.0)).unit("N.s/m").range(0.0, 1e4)
        .desc("Translational damping of the pedicel joint"),
    PEDICEL_BEND_STIFFNESS = Var::param("pedicel_bend_stiffness", Start::Float64(0.3)).unit("N.m/rad").range(1e-4, 1e4)
        .desc("Bending stiffness of the pedicel joint (estimate)"),
    PEDICEL_TWIST_STIFFNESS = Var::param("pedicel_twist_stiffness", Start::Float64(0.06)).unit("N.m/rad").range(1e-4, 1e4)
        .desc("Twisting stiffness of the pedicel joint (estimate)"),
    PEDICEL_ROT_DAMPING = Var::param("pedicel_rot_damping", Start::Float64(0.005)).unit("N.m.s/rad").range(0.0, 100.0)
        .desc("Rotational damping of the pedicel joint"),
    BRUISE_GRIP_FORCE = Var::param("bruise_grip_force", Start::Float64(40.0)).unit("N").range(0.0, 1000.0)
        .desc("A held fruit squeezed harder than this is bruised (estimate; Zheng et al. 2023, Agriculture 13:2201)"),
    BRUISE_IMPACT_SPEED = Var::param("bruise_impact_speed", Start::Float64(2.0)).unit("m/s").range(0.0, 100.0)
        .desc("A released fruit faster than this before it settles is bruised (0.2 m drop: Sargent et al. 1992)"),
    RIPE_STAGE = Var::param("ripe_stage", Start::Int32(5))
        .desc("Lowest USDA ripeness stage (1..6) that is ripe; a picked fruit below it is an unripe fruit detached"),
    LEFT_GRIP_FORCE = Var::input("left_grip_force", 0.0).unit("N")
        .desc("Force the left gripper squeezes with (arm FMU's grip_force)"),
    RIGHT_GRIP_FORCE = Var::input("right_grip_force", 0.0).unit("N")
        .desc("Force the right gripper squeezes with"),
    LEFT_LOAD_FX = Var::output("left_load_fx").unit("N").init_depends_on(&[])
        .desc("Force the attached fruit's pedicel exerts on the left hand, in left_link0 (0 when nothing attached)"),
    LEFT_LOAD_FY = Var::output("left_load_fy").unit("N").init_depends_on(&[]),
    LEFT_LOAD_FZ = Var::output("left_load_fz").unit("N").init_depends_on(&[]),
    LEFT_LOAD_MX = Var::output("left_load_mx").unit("N.m").init_depends_on(&[])
        .desc("Moment of that load about the origin of left_link0, in left_link0"),
    LEFT_LOAD_MY = Var::output("left_load_my").unit("N.m").init_depends_on(&[]),
    LEFT_LOAD_MZ = Var::output("left_load_mz").unit("N.m").init_depends_on(&[]),
    RIGHT_LOAD_FX = Var::output("right_load_fx").unit("N").init_depends_on(&[])
        .desc("Force the attached fruit's pedicel exerts on the right hand, in right_link0"),
    RIGHT_LOAD_FY = Var::output("right_load_fy").unit("N").init_depends_on(&[]),
    RIGHT_LOAD_FZ = Var::output("right_load_fz").unit("N").init_depends_on(&[]),
    RIGHT_LOAD_MX = Var::output("right_load_mx").unit("N.m").init_depends_on(&[])
        .desc("Moment of that load about the origin of right_link0, in right_link0"),
    RIGHT_LOAD_MY = Var::output("right_load_my").unit("N.m").init_depends_on(&[]),
    RIGHT_LOAD_MZ = Var::output("right_load_mz").unit("N.m").init_depends_on(&[]),
    LEFT_PEDICEL_PULL = Var::output("left_pedicel_pull").unit("N").init_depends_on(&[])
        .desc("Tension at the abscission zone of the fruit attached in the left hand (0 when none)"),
    LEFT_PEDICEL_BEND = Var::output("left_pedicel_bend").unit("N.m").init_depends_on(&[])
        .desc("Bending moment at that abscission zone"),
    LEFT_PEDICEL_TWIST = Var::output("left_pedicel_twist").unit("N.m").init_depends_on(&[])
        .desc("Twisting moment at that abscission zone"),
    RIGHT_PEDICEL_PULL = Var::output("right_pedicel_pull").unit("N").init_depends_on(&[]),
    RIGHT_PEDICEL_BEND = Var::output("right_pedicel_bend").unit("N.m").init_depends_on(&[]),
    RIGHT_PEDICEL_TWIST = Var::output("right_pedicel_twist").unit("N.m").init_depends_on(&[]),
    DETACHED_PULL_COUNT = Var::output_discrete("detached_pull_count", Start::Int32(0)).init_depends_on(&[])
        .desc("Pedicels broken by their tension (cumulative)"),
    DETACHED_BEND_COUNT = Var::output_discrete("detached_bend_count", Start::Int32(0)).init_depends_on(&[])
        .desc("Pedicels broken by bending (cumulative)"),
    DETACHED_TWIST_COUNT = Var::output_discrete("detached_twist_count", Start::Int32(0)).init_depends_on(&[])
        .desc("Pedicels broken by twisting (cumulative)"),
    LAST_DETACH_MODE = Var::output_discrete("last_detach_mode", Start::Int32(0)).init_depends_on(&[])
        .desc("How the last pedicel broke: 0 none yet, 1 pull, 2 bend, 3 twist"),
    LAST_DETACH_FORCE = Var::output("last_detach_force").unit("N").init_depends_on(&[])
        .desc("Magnitude of the pedicel force on the fruit (= at the gripper) when the last pedicel broke"),
    LAST_DETACH_MOMENT = Var::output("last_detach_moment").unit("N.m").init_depends_on(&[])
        .desc("Larger of the bending and twisting moment at the abscission zone when the last pedicel broke"),
    BRUISED_COUNT = Var::output_discrete("bruised_count", Start::Int32(0)).init_depends_on(&[])
        .desc("Fruit bruised by grip or impact (ground truth; each fruit once)"),
    GRIP_BRUISED_COUNT = Var::output_discrete("grip_bruised_count", Start::Int32(0)).init_depends_on(&[])
        .desc("Fruit squeezed above bruise_grip_force"),
    IMPACT_BRUISED_COUNT = Var::output_discrete("impact_bruised_count", Start::Int32(0)).init_depends_on(&[])
        .desc("Released fruit that went faster than bruise_impact_speed before they settled"),
    UNRIPE_DETACHED_COUNT = Var::output_discrete("unripe_detached_count", Start::Int32(0)).init_depends_on(&[])
        .desc("Fruit below ripe_stage detached from their plant"),
    PLANT_DAMAGE = Var::output_discrete("plant_damage", Start::Binary(&[])).mime(PLANT_DAMAGE_MIME).init_depends_on(&[Var::TIME])
        .desc("agrisim_msgs/PlantDamage (ground truth, for the judge): damage counts by kind and the last detachment, at the start and whenever they change"),
    PLANT_DAMAGE_SEQ = Var::output_discrete("plant_damage_seq", Start::Int64(0)).init_depends_on(&[])
        .desc("Sequence number of the newest message in plant_damage"),
    STEM_MODULUS = Var::param("stem_modulus", Start::Float64(100e6)).unit("Pa").range(1e5, 1e11)
        .desc("Young's modulus of the main stems, beams supported at foot and head (estimate from a herbaceous stem: Agriculture 12(10):1519, 2022)"),
    STEM_STRENGTH = Var::param("stem_strength", Start::Float64(7e6)).unit("Pa").range(1e3, 1e10)
        .desc("Bending strength (modulus of rupture) of the main stems: a press whose bending moment exceeds it breaks the stem (estimate, same source)"),
    STEMS_BROKEN_COUNT = Var::output_discrete("stems_broken_count", Start::Int32(0)).init_depends_on(&[])
        .desc("Main stems a robot part pressed beyond their bending strength (ground truth; each stem once)"),
    PEAK_STEM_LOAD = Var::output("peak_stem_load").init_depends_on(&[])
        .desc("Largest bending moment a robot part put on a main stem so far, as a fraction of its strength (1: broken)"),
    PEAK_STEM_FORCE = Var::output("peak_stem_force").unit("N").init_depends_on(&[])
        .desc("Lateral force of the press that gave peak_stem_load"),
    LEAF_COMPLIANT = Var::param("leaf_compliant", Start::Boolean(true))
        .desc("Whether leaves give way to the robot, turning about the petiole's base, and spring back (false: rigid)"),
    LEAF_STIFFNESS = Var::param("leaf_stiffness", Start::Float64(0.3)).unit("N.m/rad").range(1e-6, 1e6)
        .desc("Rotational stiffness of a leaf about its petiole's base (estimate)"),
    LEAF_FREQUENCY = Var::param("leaf_frequency", Start::Float64(2.0)).unit("Hz").range(0.01, 100.0)
        .desc("Natural frequency of a released leaf swinging back (estimate)"),
    LEAF_DAMPING_RATIO = Var::param("leaf_damping_ratio", Start::Float64(0.5)).range(0.0, 10.0)
        .desc("Damping ratio of a released leaf swinging back (estimate)"),
    LEAF_PUSHES = Var::output_discrete("leaf_pushes", Start::Int32(0)).init_depends_on(&[])
        .desc("Times a robot part started pressing a leaf aside (cumulative)"),
    MOVING_LEAVES = Var::output_discrete("moving_leaves", Start::Int32(0)).init_depends_on(&[])
        .desc("Leaves now turned from their grown pose (pressed, or swinging back)"),
    PEAK_LEAF_FORCE = Var::output("peak_leaf_force").unit("N").init_depends_on(&[])
        .desc("Largest force the robot spent holding a leaf aside so far"),
    TRUSS_COMPLIANT = Var::param("truss_compliant", Start::Boolean(false))
        .desc("Whether trusses give way to the robot, turning about where they leave the stem with their pedicels and hanging fruit, and spring back (false: rigid)"),
    TRUSS_STIFFNESS = Var::param("truss_stiffness", Start::Float64(1.5)).unit("N.m/rad").range(1e-6, 1e6)
        .desc("Rotational stiffness of a truss about where it leaves the stem (estimate)"),
    TRUSS_FREQUENCY = Var::param("truss_frequency", Start::Float64(2.5)).unit("Hz").range(0.01, 100.0)
        .desc("Natural frequency of a released truss swinging back (estimate)"),
    TRUSS_DAMPING_RATIO = Var::param("truss_damping_ratio", Start::Float64(0.3)).range(0.0, 10.0)
        .desc("Damping ratio of a released truss swinging back (estimate)"),
    TRUSS_PUSHES = Var::output_discrete("truss_pushes", Start::Int32(0)).init_depends_on(&[])
        .desc("Times a robot part started pressing a truss or one of its pedicels aside (cumulative)"),
    MOVING_TRUSSES = Var::output_discrete("moving_trusses", Start::Int32(0)).init_depends_on(&[])
        .desc("Trusses and pedicels now turned from their grown pose (pressed, or swinging back)"),
    PEAK_TRUSS_FORCE = Var::output("peak_truss_force").unit("N").init_depends_on(&[])
        .desc("Largest force the robot spent holding a truss or a pedicel aside so far"),
    MOVED_OBJECTS = Var::output_discrete("moved_objects", Start::Binary(&[])).mime(MOVED_OBJECTS_MIME).init_depends_on(&[Var::TIME])
        .desc("agrisim_msgs/MovedObjects (ground truth, for the sensor FMUs' moved_objects input): every scene object away from where the greenhouse grew it (pushed leaves, picked fruit) with its placement, at the start and whenever it changes"),
    MOVED_OBJECTS_SEQ = Var::output_discrete("moved_objects_seq", Start::Int64(0)).init_depends_on(&[])
        .desc("Sequence number of the newest message in moved_objects"),
}}

/// The robot's configuration inputs: base pose, lift, arm joints, finger gaps.
const ROBOT: &[usize] = &[
    BASE_X,
    BASE_Y,
    BASE_YAW,
    LIFT_POSITION,
    LEFT_Q1,
    LEFT_Q2,
    LEFT_Q3,
    LEFT_Q4,
    LEFT_Q5,
    LEFT_Q6,
    LEFT_Q7,
    RIGHT_Q1,
    RIGHT_Q2,
    RIGHT_Q3,
    RIGHT_Q4,
    RIGHT_Q5,
    RIGHT_Q6,
    RIGHT_Q7,
    LEFT_FINGER_WIDTH,
    RIGHT_FINGER_WIDTH,
];
/// What the contacts at the start depend on: the scene, the base box and the robot's configuration.
const CONTACTS: [usize; 26] =
    agrisim_fmi::concat(&[&[SCENE, SEED, BASE_LENGTH, BASE_WIDTH, BASE_HEIGHT, BASE_CLEARANCE], ROBOT]);
/// The first collision_state: the contacts, stamped on the collision_rate grid.
const COLLISION_REPORT: [usize; 28] = agrisim_fmi::concat(&[&CONTACTS, &[COLLISION_RATE, Var::TIME]]);
/// Which fruit is the target (and where it is).
const TARGET_CHOICE: &[usize] = &[SCENE, SEED, TARGET_FRUIT];
