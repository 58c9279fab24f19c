//! The ScalarsToOdometry variable table. Inputs are named like the chassis's ground-truth
//! outputs (x, y, yaw, vx, vy, wz) and the scalar odometry outputs like the chassis's
//! (odom_x ... odom_wz), so connections read the same as with the built-in chassis.

use agrisim_fmi::{Start, Var};
use agrisim_msgs::nav_msgs::Odometry;
use agrisim_msgs::tf2_msgs::TFMessage;

agrisim_fmi::variables! { pub VARIABLES {
    // --- parameters ---
    RATE = Var::param("rate", Start::Float64(10.0)).unit("Hz").range(0.001, 1000.0)
        .desc("Publication rate of odom and tf, scheduled on simulation time (like the chassis's odom_rate)"),
    PORT_WINDOW = agrisim_fmi::port_window(),
    SEED = Var::param("seed", Start::Int32(0)).desc("Seed of the odometry noise"),
    V_NOISE = Var::param("v_noise", Start::Float64(0.0)).unit("m/s").range(0.0, 100.0)
        .desc("Noise on the measured vx and vy, 1 sigma per step (0: exact)"),
    WZ_NOISE = Var::param("wz_noise", Start::Float64(0.0)).unit("rad/s").range(0.0, 100.0)
        .desc("Noise on the measured wz, 1 sigma per step (0: exact)"),
    V_SCALE_ERROR = Var::param("v_scale_error", Start::Float64(0.0)).range(-0.5, 0.5)
        .desc("Relative scale error of the measured vx and vy (0.01: odometry reads 1 % fast, as a miscalibrated wheel radius)"),
    WZ_SCALE_ERROR = Var::param("wz_scale_error", Start::Float64(0.0)).range(-0.5, 0.5)
        .desc("Relative scale error of the measured wz (a miscalibrated track width)"),
    // --- inputs: the model's ground truth ---
    X = Var::input("x", 0.0).unit("m").desc("Ground-truth x of base_link in the map frame; read at initialization only (the odom origin)"),
    Y = Var::input("y", 0.0).unit("m").desc("Ground-truth y of base_link in the map frame; read at initialization only"),
    YAW = Var::input("yaw", 0.0).unit("rad").desc("Ground-truth yaw of base_link in the map frame; read at initialization only"),
    VX = Var::input("vx", 0.0).unit("m/s").desc("Forward velocity (base frame), held over each step and integrated"),
    VY = Var::input("vy", 0.0).unit("m/s").desc("Left velocity (base frame), held over each step and integrated"),
    WZ = Var::input("wz", 0.0).unit("rad/s").desc("Yaw rate, held over each step and integrated"),
    // --- outputs ---
    ODOM_X = Var::output("odom_x").unit("m").init_depends_on(&[X]).desc("Dead-reckoned x of base_link in the odom frame"),
    ODOM_Y = Var::output("odom_y").unit("m").init_depends_on(&[Y]),
    ODOM_YAW = Var::output("odom_yaw").unit("rad").init_depends_on(&[YAW]),
    ODOM_VX = Var::output("odom_vx").unit("m/s").init_depends_on(&[VX, V_SCALE_ERROR])
        .desc("Measured forward velocity (with the noise model)"),
    ODOM_VY = Var::output("odom_vy").unit("m/s").init_depends_on(&[VY, V_SCALE_ERROR]),
    ODOM_WZ = Var::output("odom_wz").unit("rad/s").init_depends_on(&[WZ, WZ_SCALE_ERROR]),
    ODOM = Var::output_discrete("odom", Start::Binary(&[])).mime(Odometry::MIME_TYPE).max_size(agrisim_fmi::port::frames_max_size(1024, 1024))
        .init_depends_on(FIRST_MESSAGE)
        .desc("Odometry as nav_msgs/Odometry (odom -> base_link), at rate: the messages of the last port_window (CDR frames)"),
    ODOM_SEQ = Var::output_discrete("odom_seq", Start::Int64(0)).init_depends_on(&[RATE, Var::TIME])
        .desc("Sequence number of the newest message in odom"),
    TF = Var::output_discrete("tf", Start::Binary(&[])).mime(TFMessage::MIME_TYPE).max_size(agrisim_fmi::port::frames_max_size(1024, 1024))
        .init_depends_on(FIRST_MESSAGE)
        .desc("The odom -> base_link transform as tf2_msgs/TFMessage, with every odom message (CDR frames)"),
    TF_SEQ = Var::output_discrete("tf_seq", Start::Int64(0)).init_depends_on(&[RATE, Var::TIME])
        .desc("Sequence number of the newest message in tf"),
}}

/// What the messages published at initialization depend on: whether one is due (rate,
/// start time), their pose and twist, and the window they stay in.
const FIRST_MESSAGE: &[usize] = &[RATE, PORT_WINDOW, X, Y, YAW, VX, VY, WZ, V_SCALE_ERROR, WZ_SCALE_ERROR, Var::TIME];
