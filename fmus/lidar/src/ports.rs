//! The LiDAR's variable table. Scene parameters and the base box match the Greenhouse (world)
//! FMU's, so both see the same geometry from the same scenario text.

use crate::datasheet as ds;
use agrisim_fmi::{Start, Var};

/// MIME type of the message port (FMI 3 Binary carrying ROS 2 CDR).
pub const POINTS_MIME: &str = "application/x-ros2-cdr; type=sensor_msgs/msg/PointCloud2";

agrisim_fmi::variables! { pub VARIABLES {
    // --- scene ---
    SCENE = Var::param("scene", Start::String(""))
        .desc("The keys of the scenario's [greenhouse] table as TOML (no header); empty = the default greenhouse"),
    SEED = Var::param("scene_seed", Start::Int32(-1))
        .desc("Seed of the greenhouse generator; < 0 = the scene's own seed key (as the world FMU)"),
    ENVIRONMENT = Var::param("environment", Start::String(""))
        .desc("The keys of the scenario's [environment] table as TOML (no header); fog, rain and haze attenuate returns (two-way Koschmieder extinction); empty = clear air, no attenuation"),
    // --- sensor (Livox MID-360 defaults) ---
    NOISE_SEED = Var::param("seed", Start::Int32(0)).desc("Seed of the range noise (set per run by the orchestrator)"),
    FRAME_RATE = Var::param("frame_rate", Start::Float64(ds::FRAME_RATE)).unit("Hz").range(0.1, 1000.0)
        .desc("Frames per second of simulation time"),
    POINT_RATE = Var::param("point_rate", Start::Float64(ds::POINT_RATE)).unit("1/s").range(1.0, 2.0e6)
        .desc("Points per second (one ray each); a frame holds point_rate / frame_rate of them (at most 1e6)"),
    RANGE_MIN = Var::param("range_min", Start::Float64(ds::RANGE_MIN)).unit("m").range(0.0, 1000.0)
        .desc("Blind zone: nothing nearer returns"),
    RANGE_MAX = Var::param("range_max", Start::Float64(ds::RANGE_MAX)).unit("m").range(0.01, 1000.0)
        .desc("Detection range (MID-360: 40 m at 10 % reflectivity)"),
    RANGE_NOISE = Var::param("range_noise", Start::Float64(ds::RANGE_NOISE)).unit("m").range(0.0, 10.0)
        .desc("Range noise, 1 sigma (MID-360: 2 cm)"),
    ELEVATION_MIN = Var::param("elevation_min", Start::Float64(ds::FOV_ELEVATION_MIN_DEG)).unit("deg").range(-89.0, 89.0)
        .desc("Lower edge of the vertical field of view"),
    ELEVATION_MAX = Var::param("elevation_max", Start::Float64(ds::FOV_ELEVATION_MAX_DEG)).unit("deg").range(-89.0, 89.0)
        .desc("Upper edge of the vertical field of view"),
    FRAME_ID = Var::param("frame_id", Start::String("lidar_link")).desc("header.frame_id of the clouds"),
    DESKEWED = Var::param("deskewed", Start::Boolean(false))
        .desc("false: each point is measured from the pose at its own time, header.stamp = first point (as the sensor); true: all points from the pose at the frame's end, header.stamp = frame end"),
    DROP_NO_RETURN = Var::param("drop_no_return", Start::Boolean(false))
        .desc("Leave rays without a return out of the cloud (default: kept at (0,0,0), as the Livox driver does)"),
    // --- mount on base_link ---
    MOUNT_X = Var::param("mount_x", Start::Float64(0.0)).unit("m").desc("lidar_link position on base_link (default: on top of the robot)"),
    MOUNT_Y = Var::param("mount_y", Start::Float64(0.0)).unit("m"),
    MOUNT_Z = Var::param("mount_z", Start::Float64(1.0)).unit("m"),
    MOUNT_ROLL = Var::param("mount_roll", Start::Float64(0.0)).unit("rad")
        .desc("lidar_link orientation on base_link, roll-pitch-yaw about fixed axes (URDF)"),
    MOUNT_PITCH = Var::param("mount_pitch", Start::Float64(0.0)).unit("rad"),
    MOUNT_YAW = Var::param("mount_yaw", Start::Float64(0.0)).unit("rad"),
    // --- the robot's own base box (a moving obstacle for the rays) ---
    BASE_LENGTH = Var::param("base_length", Start::Float64(1.2)).unit("m").range(0.01, 20.0)
        .desc("Robot base box extent along base_link x"),
    BASE_WIDTH = Var::param("base_width", Start::Float64(0.9)).unit("m").range(0.01, 20.0),
    BASE_HEIGHT = Var::param("base_height", Start::Float64(0.6)).unit("m").range(0.01, 20.0),
    BASE_CLEARANCE = Var::param("base_clearance", Start::Float64(0.05)).unit("m").range(0.0, 5.0)
        .desc("Height of the box bottom above the floor (base_link is on the floor)"),
    // --- inputs: chassis ground truth ---
    BASE_X = Var::input("base_x", 0.0).unit("m").desc("x of base_link in the map frame"),
    BASE_Y = Var::input("base_y", 0.0).unit("m").desc("y of base_link in the map frame"),
    BASE_YAW = Var::input("base_yaw", 0.0).unit("rad").desc("Yaw of base_link in the map frame"),
    // --- outputs ---
    POINTS = Var::output_discrete("points", Start::Binary(&[])).mime(POINTS_MIME)
        .desc("The latest frame as sensor_msgs/PointCloud2 (CDR) in lidar_link: float32 x, y, z, intensity, t"),
    POINTS_SEQ = Var::output_discrete("points_seq", Start::Int64(0)).desc("Sequence counter of points"),
    POINTS_IN_FRAME = Var::output_discrete("points_in_frame", Start::Int32(0)).desc("Points in the latest cloud"),
    VISIBILITY = Var::output_discrete("visibility", Start::Float64(0.0)).unit("m")
        .desc("Meteorological visibility of the environment; 0 = no environment (clear air)"),
    RETURNS_IN_FRAME = Var::output_discrete("returns_in_frame", Start::Int32(0))
        .desc("Points of the latest cloud that are returns (the others are no-return placeholders)"),
}}
