//! The LiDAR's variable table. Scene parameters, mount, base box and base pose inputs are the
//! shared sensor ports (`agrisim_sensor_ports`, as the camera FMU's), so all
//! sensors and the world see the same geometry from the same scenario text.

use crate::datasheet as ds;
use agrisim_fmi::{Start, Var};

/// MIME type of the message port (FMI 3 Binary carrying ROS 2 CDR).
pub const POINTS_MIME: &str = "application/x-ros2-cdr-frames; version=1; type=sensor_msgs/msg/PointCloud2";

/// maxSize of `points`: the most points a frame holds, plus 4 KiB for the header, field
/// descriptions and frame_id.
/// Most points one frame may hold (point_rate / frame_rate is checked against it).
pub const MAX_POINTS_PER_FRAME: usize = 1_000_000;
pub const MAX_CLOUD: usize = MAX_POINTS_PER_FRAME * crate::cloud::POINT_STEP + 4096;

// lidar_link on base_link (default: on top of the robot).
agrisim_sensor_ports::sensor_variables! { pub VARIABLES {
  mount: "lidar_link" (0.0, 0.0, 1.0),
  params: {
    ENVIRONMENT = Var::param("environment", Start::String(""))
        .desc("The keys of the scenario's [environment] table as TOML (no header); fog, rain and haze attenuate returns (two-way Koschmieder extinction); empty = clear air, no attenuation"),
    CAST_THREADS = Var::param("cast_threads", Start::Int32(2))
        .desc("Threads casting a frame's rays, 1-64 (results do not depend on it)"),
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
    PORT_WINDOW = agrisim_fmi::port_window(),
  },
  ports: {
    // --- outputs (no frame at initialization: it would cover time before the run) ---
    POINTS = Var::output_discrete("points", Start::Binary(&[])).mime(POINTS_MIME).max_size(agrisim_fmi::port::frames_max_size(MAX_CLOUD, 4)).init_depends_on(&[])
        .desc("The frames of the last port_window as sensor_msgs/PointCloud2 (CDR frames) in lidar_link: float32 x, y, z, intensity, t"),
    POINTS_SEQ = Var::output_discrete("points_seq", Start::Int64(0)).init_depends_on(&[]).desc("Sequence number of the newest frame in points"),
    POINTS_IN_FRAME = Var::output_discrete("points_in_frame", Start::Int32(0)).init_depends_on(&[])
        .desc("Points in the latest cloud"),
    VISIBILITY = Var::output_discrete("visibility", Start::Float64(0.0)).unit("m").init_depends_on(&[ENVIRONMENT])
        .desc("Meteorological visibility of the environment; 0 = no environment (clear air)"),
    RETURNS_IN_FRAME = Var::output_discrete("returns_in_frame", Start::Int32(0)).init_depends_on(&[])
        .desc("Points of the latest cloud that are returns (the others are no-return placeholders)"),
  },
}}
