//! The Greenhouse FMU's variable table: scene parameters, the robot pose coming in from the
//! other FMUs, contact and clearance outputs, and ground-truth fruit poses.

use agrisim_fmi::{Start, Var};

/// MIME types of the message ports (FMI 3 Binary variables carrying ROS 2 CDR).
pub const COLLISION_STATE_MIME: &str = "application/x-ros2-cdr; type=agrisim_msgs/msg/CollisionState";
pub const POSE_ARRAY_MIME: &str = "application/x-ros2-cdr; type=geometry_msgs/msg/PoseArray";
pub const POSE_STAMPED_MIME: &str = "application/x-ros2-cdr; type=geometry_msgs/msg/PoseStamped";

agrisim_fmi::variables! { pub VARIABLES {
    // --- scene (fixed parameters) ---
    SCENE = Var::param("scene", Start::String(""))
        .desc("The keys of the scenario's [greenhouse] table as TOML (no header); empty = the default greenhouse"),
    SEED = Var::param("scene_seed", Start::Int32(-1))
        .desc("Seed of the greenhouse generator (plants, fruit, random obstacles); < 0 = the scene's own seed key"),
    // --- robot base box (fixed parameters) ---
    BASE_LENGTH = Var::param("base_length", Start::Float64(1.2)).unit("m").range(0.01, 20.0)
        .desc("Robot base box extent along base_link x"),
    BASE_WIDTH = Var::param("base_width", Start::Float64(0.9)).unit("m").range(0.01, 20.0)
        .desc("Robot base box extent along base_link y"),
    BASE_HEIGHT = Var::param("base_height", Start::Float64(0.6)).unit("m").range(0.01, 20.0)
        .desc("Robot base box extent along z"),
    BASE_CLEARANCE = Var::param("base_clearance", Start::Float64(0.05)).unit("m").range(0.0, 5.0)
        .desc("Height of the box bottom above the floor; the box spans the navigation height band"),
    CLEARANCE_CAP = Var::param("clearance_cap", Start::Float64(5.0)).unit("m").range(0.01, 1000.0)
        .desc("min_clearance reports at most this distance (nothing nearer than the cap)"),
    // --- publication rates (fixed parameters) ---
    COLLISION_RATE = Var::param("collision_rate", Start::Float64(10.0)).unit("Hz").range(0.001, 1e6)
        .desc("Publication rate of collision_state (it is also published at once when the contact set changes)"),
    FRUIT_RATE = Var::param("fruit_rate", Start::Float64(1.0)).unit("Hz").range(0.001, 1e6)
        .desc("Publication rate of fruit_poses and target"),
    // --- inputs: robot pose (ground truth of the chassis and lift FMUs) ---
    BASE_X = Var::input("base_x", 0.0).unit("m").desc("x of base_link in the map frame"),
    BASE_Y = Var::input("base_y", 0.0).unit("m").desc("y of base_link in the map frame"),
    BASE_YAW = Var::input("base_yaw", 0.0).unit("rad").desc("Yaw of base_link in the map frame"),
    LIFT_POSITION = Var::input("lift_position", 0.0).unit("m")
        .desc("Lift extension (reserved for the arm links; not yet part of the robot geometry)"),
    TARGET_FRUIT = Var::input_discrete("target_fruit", Start::Int32(-1))
        .desc("Index into the fruit list (order of fruit_poses) whose pose is the target; -1 = none"),
    // --- outputs: contacts and clearance ---
    COLLISION = Var::output_discrete("collision", Start::Boolean(false))
        .desc("The robot touches or penetrates any scene object (floor excluded)"),
    COLLISION_COUNT = Var::output_discrete("collision_count", Start::Int32(0))
        .desc("Cumulative number of contact onsets (an object coming into contact with the robot)"),
    MIN_CLEARANCE = Var::output("min_clearance").unit("m")
        .desc("Distance from the base box to the nearest scene object within the base's height band, capped at clearance_cap"),
    COLLISION_STATE = Var::output_discrete("collision_state", Start::Binary(&[])).mime(COLLISION_STATE_MIME)
        .desc("agrisim_msgs/CollisionState in the map frame, at collision_rate and whenever the contact set changes"),
    COLLISION_STATE_SEQ = Var::output_discrete("collision_state_seq", Start::Int64(0))
        .desc("Sequence counter of collision_state"),
    // --- outputs: ground truth ---
    FRUIT_COUNT = Var::output_discrete("fruit_count", Start::Int32(0)).desc("Number of fruit in the scene"),
    FRUIT_POSES = Var::output_discrete("fruit_poses", Start::Binary(&[])).mime(POSE_ARRAY_MIME)
        .desc("geometry_msgs/PoseArray of every fruit centre (frame map), at fruit_rate"),
    FRUIT_POSES_SEQ = Var::output_discrete("fruit_poses_seq", Start::Int64(0)).desc("Sequence counter of fruit_poses"),
    TARGET_VALID = Var::output_discrete("target_valid", Start::Boolean(false))
        .desc("target_fruit names an existing fruit"),
    TARGET_ID = Var::output_discrete("target_id", Start::Int32(-1))
        .desc("Scene object id of the target fruit (as in collision_state), -1 when none"),
    TARGET_X = Var::output("target_x").unit("m").desc("Target fruit centre in the map frame (0 when none)"),
    TARGET_Y = Var::output("target_y").unit("m"),
    TARGET_Z = Var::output("target_z").unit("m"),
    TARGET = Var::output_discrete("target", Start::Binary(&[])).mime(POSE_STAMPED_MIME)
        .desc("geometry_msgs/PoseStamped of the target fruit (frame map), at fruit_rate and when target_fruit changes"),
    TARGET_SEQ = Var::output_discrete("target_seq", Start::Int64(0)).desc("Sequence counter of target"),
}}
