//! The IMU's variable table. Noise parameters follow gz-sensors' names per sensor
//! (`gyro_*`, `accel_*`), except that the white noise is given as a density (datasheets do)
//! and `*_bias_instability` is added (see [`crate::noise`]). Defaults: [`crate::datasheet`].

use crate::datasheet as ds;
use agrisim_fmi::{Start, Var};

/// MIME type of the message port (FMI 3 Binary carrying ROS 2 CDR).
pub const IMU_MIME: &str = "application/x-ros2-cdr-frames; version=1; type=sensor_msgs/msg/Imu";

agrisim_fmi::variables! { pub VARIABLES {
    // --- sampling, frame, mount ---
    RATE = Var::param("rate", Start::Float64(200.0)).unit("Hz").range(0.001, 100_000.0)
        .desc("Sample rate on simulation time; the port carries every sample"),
    PORT_WINDOW = agrisim_fmi::port_window(),
    SEED = Var::param("seed", Start::Int32(0)).desc("Seed of every noise process"),
    FRAME_ID = Var::param("frame_id", Start::String("imu_link")).desc("header.frame_id of the messages"),
    MOUNT_X = Var::param("mount_x", Start::Float64(0.0)).unit("m")
        .desc("IMU position on base_link (default: inside the LiDAR on the mast, as in the MID-360)"),
    MOUNT_Y = Var::param("mount_y", Start::Float64(0.0)).unit("m"),
    MOUNT_Z = Var::param("mount_z", Start::Float64(1.0)).unit("m"),
    MOUNT_ROLL = Var::param("mount_roll", Start::Float64(0.0)).unit("rad")
        .desc("IMU orientation on base_link, roll-pitch-yaw about fixed axes (URDF)"),
    MOUNT_PITCH = Var::param("mount_pitch", Start::Float64(0.0)).unit("rad"),
    MOUNT_YAW = Var::param("mount_yaw", Start::Float64(0.0)).unit("rad"),
    GRAVITY = Var::param("gravity", Start::Float64(ds::STANDARD_GRAVITY)).unit("m/s2").range(0.0, 100.0),
    ENABLE_ORIENTATION = Var::param("enable_orientation", Start::Boolean(true))
        .desc("Publish the true orientation in the map frame (as gz does); false: covariance[0] = -1 (REP 145)"),
    // --- gyroscope noise ---
    GYRO_NOISE_DENSITY = Var::param("gyro_noise_density", Start::Float64(ds::GYRO_NOISE_DENSITY)).unit("rad/s/sqrt(Hz)")
        .desc("White noise density (ICM-40609-D: 4.5 mdps/sqrt(Hz))"),
    GYRO_BIAS_MEAN = Var::param("gyro_bias_mean", Start::Float64(0.0)).unit("rad/s")
        .desc("Turn-on bias magnitude mean (gz bias_mean; sign random)"),
    GYRO_BIAS_STDDEV = Var::param("gyro_bias_stddev", Start::Float64(ds::GYRO_TURN_ON_BIAS_STDDEV)).unit("rad/s")
        .desc("Turn-on bias spread (gz bias_stddev; 10 mdps/degC x 10 degC)"),
    GYRO_DYNAMIC_BIAS_STDDEV = Var::param("gyro_dynamic_bias_stddev", Start::Float64(ds::GYRO_RANDOM_WALK)).unit("rad/s2/sqrt(Hz)")
        .desc("gz dynamic bias driving density: the bias random walk"),
    GYRO_DYNAMIC_BIAS_CORRELATION_TIME = Var::param("gyro_dynamic_bias_correlation_time", Start::Float64(ds::RANDOM_WALK_CORRELATION_TIME)).unit("s"),
    GYRO_BIAS_INSTABILITY = Var::param("gyro_bias_instability", Start::Float64(ds::GYRO_BIAS_INSTABILITY)).unit("rad/s")
        .desc("Bias instability B (Allan floor 0.664 B; 4.6 deg/h, Greenheck 2009)"),
    // --- accelerometer noise ---
    ACCEL_NOISE_DENSITY = Var::param("accel_noise_density", Start::Float64(ds::ACCEL_NOISE_DENSITY)).unit("m/s2/sqrt(Hz)")
        .desc("White noise density (ICM-40609-D: 100 ug/sqrt(Hz))"),
    ACCEL_BIAS_MEAN = Var::param("accel_bias_mean", Start::Float64(0.0)).unit("m/s2"),
    ACCEL_BIAS_STDDEV = Var::param("accel_bias_stddev", Start::Float64(ds::ACCEL_TURN_ON_BIAS_STDDEV)).unit("m/s2")
        .desc("Turn-on bias spread (0.15 mg/degC x 10 degC)"),
    ACCEL_DYNAMIC_BIAS_STDDEV = Var::param("accel_dynamic_bias_stddev", Start::Float64(ds::ACCEL_RANDOM_WALK)).unit("m/s3/sqrt(Hz)"),
    ACCEL_DYNAMIC_BIAS_CORRELATION_TIME = Var::param("accel_dynamic_bias_correlation_time", Start::Float64(ds::RANDOM_WALK_CORRELATION_TIME)).unit("s"),
    ACCEL_BIAS_INSTABILITY = Var::param("accel_bias_instability", Start::Float64(ds::ACCEL_BIAS_INSTABILITY)).unit("m/s2")
        .desc("Bias instability B (36 ug, Greenheck 2009)"),
    // --- inputs: chassis ground truth ---
    BASE_X = Var::input("base_x", 0.0).unit("m").desc("Ground-truth base_link x (not needed by the IMU; accepted so sensors connect alike)"),
    BASE_Y = Var::input("base_y", 0.0).unit("m"),
    BASE_YAW = Var::input("base_yaw", 0.0).unit("rad").desc("Ground-truth base_link yaw in the map frame"),
    VX = Var::input("vx", 0.0).unit("m/s").desc("Ground-truth forward velocity (base frame)"),
    VY = Var::input("vy", 0.0).unit("m/s"),
    WZ = Var::input("wz", 0.0).unit("rad/s"),
    // --- outputs: the latest sample (at initialization: the sample at the start time) ---
    GYRO_X = Var::output("gyro_x").unit("rad/s").init_depends_on(SAMPLE).desc("Latest angular velocity sample, IMU frame"),
    GYRO_Y = Var::output("gyro_y").unit("rad/s").init_depends_on(SAMPLE),
    GYRO_Z = Var::output("gyro_z").unit("rad/s").init_depends_on(SAMPLE),
    ACCEL_X = Var::output("accel_x").unit("m/s2").init_depends_on(SAMPLE).desc("Latest specific force sample, IMU frame"),
    ACCEL_Y = Var::output("accel_y").unit("m/s2").init_depends_on(SAMPLE),
    ACCEL_Z = Var::output("accel_z").unit("m/s2").init_depends_on(SAMPLE),
    IMU = Var::output_discrete("imu", Start::Binary(&[])).mime(IMU_MIME).max_size(agrisim_fmi::port::frames_max_size(4096, 1024)).init_depends_on(MESSAGE)
        .desc("Every sample of the last port_window as sensor_msgs/Imu (CDR frames), each stamped with its sample time"),
    IMU_SEQ = Var::output_discrete("imu_seq", Start::Int64(0)).init_depends_on(&[])
        .desc("Sequence number of the newest sample in imu (one per sample)"),
}}

/// What the sample at the start time depends on: the sampling and noise parameters, the
/// mount and the base motion (not its position), and the start time.
const SAMPLE: &[usize] = &[
    RATE,
    SEED,
    MOUNT_X,
    MOUNT_Y,
    MOUNT_Z,
    MOUNT_ROLL,
    MOUNT_PITCH,
    MOUNT_YAW,
    GRAVITY,
    GYRO_NOISE_DENSITY,
    GYRO_BIAS_MEAN,
    GYRO_BIAS_STDDEV,
    GYRO_DYNAMIC_BIAS_STDDEV,
    GYRO_DYNAMIC_BIAS_CORRELATION_TIME,
    GYRO_BIAS_INSTABILITY,
    ACCEL_NOISE_DENSITY,
    ACCEL_BIAS_MEAN,
    ACCEL_BIAS_STDDEV,
    ACCEL_DYNAMIC_BIAS_STDDEV,
    ACCEL_DYNAMIC_BIAS_CORRELATION_TIME,
    ACCEL_BIAS_INSTABILITY,
    BASE_YAW,
    VX,
    VY,
    WZ,
    Var::TIME,
];
/// The message adds its frame and the orientation switch to the sample.
const MESSAGE: &[usize] = &agrisim_fmi::concat::<28>(&[SAMPLE, &[FRAME_ID, ENABLE_ORIENTATION]]);

/// Gyro and accelerometer output indices in axis order.
pub const GYRO: [usize; 3] = [GYRO_X, GYRO_Y, GYRO_Z];
pub const ACCEL: [usize; 3] = [ACCEL_X, ACCEL_Y, ACCEL_Z];
