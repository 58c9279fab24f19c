//! The variable table shared by both chassis models: identical ports and value references,
//! so one can replace the other in a system without touching a connection.

use agrisim_fmi::{Start, Var};

/// MIME types of the message ports (FMI 3 Binary variables carrying ROS 2 CDR).
pub const TWIST_MIME: &str = "application/x-ros2-cdr-frames; version=1; type=geometry_msgs/msg/Twist";
pub const ODOMETRY_MIME: &str = "application/x-ros2-cdr-frames; version=1; type=nav_msgs/msg/Odometry";

agrisim_fmi::variables! { pub VARIABLES {
    // --- geometry and limits (fixed parameters) ---
    WHEEL_BASE = Var::param("wheel_base", Start::Float64(1.0)).unit("m").range(0.1, 10.0)
        .desc("Distance between front and rear axles"),
    TRACK = Var::param("track", Start::Float64(0.8)).unit("m").range(0.1, 10.0)
        .desc("Distance between left and right wheels"),
    WHEEL_RADIUS = Var::param("wheel_radius", Start::Float64(0.1)).unit("m").range(0.01, 2.0),
    STEER_MAX = Var::param("steer_max", Start::Float64(std::f64::consts::FRAC_PI_2)).unit("rad").range(0.0, 3.2)
        .desc("Steering angle limit (symmetric)"),
    STEER_RATE_MAX = Var::param("steer_rate_max", Start::Float64(3.0)).unit("rad/s").range(0.0, 1e9),
    WHEEL_SPEED_MAX = Var::param("wheel_speed_max", Start::Float64(15.0)).unit("rad/s").range(0.0, 1e9)
        .desc("Wheel spin-rate limit (15 rad/s x 0.1 m = 1.5 m/s)"),
    WHEEL_ACCEL_MAX = Var::param("wheel_accel_max", Start::Float64(10.0)).unit("rad/s2").range(0.0, 1e12)
        .desc("Wheel spin acceleration limit of the commanded profile"),
    CMD_TIMEOUT = Var::tunable("cmd_timeout", Start::Float64(0.5)).unit("s")
        .desc("Stop when no fresh command arrived for this long; <= 0 disables the watchdog"),
    X0 = Var::param("x0", Start::Float64(0.0)).unit("m").desc("Initial x in the world (map/odom) frame"),
    Y0 = Var::param("y0", Start::Float64(0.0)).unit("m"),
    YAW0 = Var::param("yaw0", Start::Float64(0.0)).unit("rad"),
    ODOM_RATE = Var::param("odom_rate", Start::Float64(10.0)).unit("Hz").range(0.001, 1e6)
        .desc("Publication rate of the odom message port, scheduled on simulation time"),
    PORT_WINDOW = agrisim_fmi::port_window(),
    SEED = Var::param("seed", Start::Int32(0)).desc("Seed of odometry noise and slip"),
    ENC_NOISE = Var::param("enc_noise", Start::Float64(0.0)).unit("rad/s")
        .desc("Wheel encoder spin-rate noise, 1 sigma per step"),
    STEER_NOISE = Var::param("steer_noise", Start::Float64(0.0)).unit("rad")
        .desc("Steering encoder noise, 1 sigma per step"),
    SLIP_MEAN = Var::param("slip_mean", Start::Float64(0.0))
        .desc("ChassisKinematic: mean longitudinal slip ratio (wheel speed not turned into motion)"),
    SLIP_STD = Var::param("slip_std", Start::Float64(0.0))
        .desc("ChassisKinematic: slip ratio noise, 1 sigma per step and wheel"),
    // --- dynamics (used by ChassisDynamic; ChassisKinematic ignores them) ---
    MASS = Var::param("mass", Start::Float64(180.0)).unit("kg").range(1.0, 1e5)
        .desc("ChassisDynamic: base mass without payload"),
    INERTIA_Z = Var::param("inertia_z", Start::Float64(30.0)).unit("kg.m2").range(0.01, 1e6)
        .desc("ChassisDynamic: yaw inertia of the base without payload"),
    CG_HEIGHT = Var::param("cg_height", Start::Float64(0.3)).unit("m")
        .desc("ChassisDynamic: centre-of-mass height of the base (load transfer)"),
    WHEEL_INERTIA = Var::param("wheel_inertia", Start::Float64(0.05)).unit("kg.m2").range(1e-4, 100.0)
        .desc("ChassisDynamic: spin inertia of wheel plus motor rotor"),
    TORQUE_MAX = Var::param("torque_max", Start::Float64(20.0)).unit("N.m").range(0.0, 1e6)
        .desc("ChassisDynamic: motor torque limit per wheel"),
    SPEED_GAIN = Var::param("speed_gain", Start::Float64(8.0)).unit("N.m.s/rad")
        .desc("ChassisDynamic: wheel speed controller proportional gain"),
    MU = Var::param("mu", Start::Float64(0.8)).range(0.0, 5.0)
        .desc("ChassisDynamic: tyre-floor friction coefficient"),
    SLIP_STIFFNESS = Var::param("slip_stiffness", Start::Float64(4000.0)).unit("N.s/m")
        .desc("ChassisDynamic: tyre force per slip velocity before saturation"),
    // --- inputs ---
    CMD_VX = Var::input("cmd_vx", 0.0).unit("m/s").desc("Scalar command: forward velocity (base frame)"),
    CMD_VY = Var::input("cmd_vy", 0.0).unit("m/s").desc("Scalar command: left velocity (base frame)"),
    CMD_WZ = Var::input("cmd_wz", 0.0).unit("rad/s").desc("Scalar command: yaw rate"),
    CMD_SEQ = Var::input_discrete("cmd_seq", Start::Int32(0))
        .desc("Scalar command counter: a change makes cmd_vx/vy/wz the active command"),
    CMD_VEL = Var::input_discrete("cmd_vel", Start::Binary(&[])).mime(TWIST_MIME).max_size(agrisim_fmi::port::frames_max_size(1024, 64))
        .desc("Message commands (geometry_msgs/Twist, CDR frames, or one bare CDR message); those after the last taken are applied in order"),
    CMD_VEL_SEQ = Var::input_discrete("cmd_vel_seq", Start::Int64(0)).desc("Sequence number of the newest command in cmd_vel"),
    PAYLOAD_MASS = Var::input("payload_mass", 0.0).unit("kg").desc("Mass carried on the base (lift, arms)"),
    PAYLOAD_HEIGHT = Var::input("payload_height", 0.0).unit("m").desc("Centre-of-mass height of the payload"),
    // --- outputs: ground truth ---
    X = Var::output("x").unit("m").init_depends_on(&[X0]).desc("Ground-truth x of base_link in the world frame"),
    Y = Var::output("y").unit("m").init_depends_on(&[Y0]),
    YAW = Var::output("yaw").unit("rad").init_depends_on(&[YAW0]),
    VX = Var::output("vx").unit("m/s").init_depends_on(&[]).desc("Ground-truth forward velocity (base frame)"),
    VY = Var::output("vy").unit("m/s").init_depends_on(&[]),
    WZ = Var::output("wz").unit("rad/s").init_depends_on(&[]),
    STEER_FL = Var::output("steer_fl").unit("rad").init_depends_on(&[]),
    STEER_FR = Var::output("steer_fr").unit("rad").init_depends_on(&[]),
    STEER_RL = Var::output("steer_rl").unit("rad").init_depends_on(&[]),
    STEER_RR = Var::output("steer_rr").unit("rad").init_depends_on(&[]),
    SPIN_FL = Var::output("spin_fl").unit("rad/s").init_depends_on(&[]),
    SPIN_FR = Var::output("spin_fr").unit("rad/s").init_depends_on(&[]),
    SPIN_RL = Var::output("spin_rl").unit("rad/s").init_depends_on(&[]),
    SPIN_RR = Var::output("spin_rr").unit("rad/s").init_depends_on(&[]),
    // --- outputs: wheel odometry (drifts with noise and slip) ---
    ODOM_X = Var::output("odom_x").unit("m").init_depends_on(&[X0]).desc("Wheel-odometry x in the odom frame"),
    ODOM_Y = Var::output("odom_y").unit("m").init_depends_on(&[Y0]),
    ODOM_YAW = Var::output("odom_yaw").unit("rad").init_depends_on(&[YAW0]),
    ODOM_VX = Var::output("odom_vx").unit("m/s").init_depends_on(&[]),
    ODOM_VY = Var::output("odom_vy").unit("m/s").init_depends_on(&[]),
    ODOM_WZ = Var::output("odom_wz").unit("rad/s").init_depends_on(&[]),
    CMD_ACTIVE = Var::output_discrete("cmd_active", Start::Boolean(false)).init_depends_on(&[CMD_TIMEOUT])
        .desc("A fresh command is being followed (false: watchdog stopped the base)"),
    ODOM = Var::output_discrete("odom", Start::Binary(&[])).mime(ODOMETRY_MIME).max_size(agrisim_fmi::port::frames_max_size(1024, 1024))
        .init_depends_on(&[X0, Y0, YAW0, ODOM_RATE, PORT_WINDOW, Var::TIME])
        .desc("Wheel odometry as nav_msgs/Odometry (odom -> base_link), at odom_rate: the messages of the last port_window (CDR frames)"),
    ODOM_SEQ = Var::output_discrete("odom_seq", Start::Int64(0)).init_depends_on(&[]).desc("Sequence number of the newest message in odom"),
}}

/// Steering output indices in wheel order.
pub const STEER: [usize; 4] = [STEER_FL, STEER_FR, STEER_RL, STEER_RR];
/// Spin output indices in wheel order.
pub const SPIN: [usize; 4] = [SPIN_FL, SPIN_FR, SPIN_RL, SPIN_RR];
