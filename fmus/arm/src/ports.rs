//! The Arm FMU's variable table. One FMU serves both arms: `side` selects the URDF joints.

use agrisim_fmi::{Start, Var};
use agrisim_msgs::agrisim::{GripperState, TrajectoryStatus};
use agrisim_msgs::control_msgs::GripperCommand;
use agrisim_msgs::sensor_msgs::JointState;
use agrisim_msgs::trajectory_msgs::JointTrajectory;

agrisim_fmi::variables! { pub VARIABLES {
    // --- parameters ---
    SIDE = Var::param("side", Start::String("left"))
        .desc("Which arm: \"left\" or \"right\" (joints {side}_joint1..7, {side}_finger_joint1/2 of the URDF)"),
    Q_INIT = Var::param("q_init", Start::String(""))
        .desc("Initial joint positions \"q1,...,q7\" in rad; empty: the ready pose 0,-pi/4,0,-3pi/4,0,pi/2,pi/4"),
    KP = Var::param("kp", Start::String(""))
        .desc("Joint stiffness \"k1,...,k7\" in N m/rad; empty: libfranka example gains 600,600,600,600,250,150,50"),
    KD = Var::param("kd", Start::String(""))
        .desc("Joint damping \"d1,...,d7\" in N m s/rad; empty: libfranka example gains 50,50,50,50,30,25,15"),
    INERTIA_SCALE = Var::param("ctrl_inertia_scale", Start::Float64(0.9)).range(0.0, 10.0)
        .desc("Controller's inertia estimate / plant inertia (model mismatch)"),
    COULOMB_SCALE = Var::param("ctrl_coulomb_scale", Start::Float64(1.2)).range(0.0, 10.0)
        .desc("Controller's Coulomb friction estimate / plant Coulomb friction"),
    VISCOUS_SCALE = Var::param("ctrl_viscous_scale", Start::Float64(0.7)).range(0.0, 10.0)
        .desc("Controller's viscous friction estimate / plant viscous friction"),
    JOINT_STATE_RATE = Var::param("joint_state_rate", Start::Float64(50.0)).unit("Hz").range(0.001, 1000.0)
        .desc("Publication rate of joint_states and gripper_state on simulation time"),
    STATUS_RATE = Var::param("status_rate", Start::Float64(10.0)).unit("Hz").range(0.001, 1000.0)
        .desc("Periodic publication rate of trajectory_status (also published on every change)"),
    GRIPPER_SPEED = Var::param("gripper_speed", Start::Float64(0.1)).unit("m/s").range(1e-6, 10.0)
        .desc("Finger gap speed"),
    GRIPPER_WIDTH0 = Var::param("gripper_width0", Start::Float64(0.08)).unit("m").range(0.0, 0.08)
        .desc("Initial finger gap"),
    POSITION_NOISE = Var::param("position_noise", Start::Float64(0.0)).unit("rad").range(0.0, 1.0)
        .desc("Std. deviation of encoder noise added to joint_states positions (not to q1..q7)"),
    SEED = Var::param("seed", Start::Int32(0)).desc("Seed of the encoder noise"),
    PORT_WINDOW = agrisim_fmi::port_window(),
    // --- inputs ---
    TRAJECTORY = Var::input_discrete("trajectory", Start::Binary(&[])).mime(JointTrajectory::MIME_TYPE).max_size(16 << 20)
        .desc("trajectory_msgs/JointTrajectory (CDR frames, or one bare CDR message); those after the last taken are taken in order, each replacing the one before"),
    TRAJECTORY_SEQ = Var::input_discrete("trajectory_seq", Start::Int64(0)).desc("Sequence number of the newest message in trajectory"),
    GRIPPER_COMMAND = Var::input_discrete("gripper_command", Start::Binary(&[])).mime(GripperCommand::MIME_TYPE).max_size(agrisim_fmi::port::frames_max_size(1024, 64))
        .desc("control_msgs/GripperCommand (CDR frames, or one bare CDR message): position = finger gap in m, max_effort in N"),
    GRIPPER_COMMAND_SEQ = Var::input_discrete("gripper_command_seq", Start::Int64(0)).desc("Sequence number of the newest message in gripper_command"),
    GRASP_WIDTH = Var::input("grasp_width", 0.0).unit("m")
        .desc("Width of the object between the fingers (world FMU); 0 = none. Closing fingers stop there"),
    // --- outputs ---
    // Initially the arm rests at q_init with the gap gripper_width0; a trajectory or gripper
    // command present at initialization is accepted or rejected (status) but not executed yet.
    Q1 = Var::output("q1").unit("rad").init_depends_on(&[Q_INIT]).desc("Actual joint 1 position"),
    Q2 = Var::output("q2").unit("rad").init_depends_on(&[Q_INIT]),
    Q3 = Var::output("q3").unit("rad").init_depends_on(&[Q_INIT]),
    Q4 = Var::output("q4").unit("rad").init_depends_on(&[Q_INIT]),
    Q5 = Var::output("q5").unit("rad").init_depends_on(&[Q_INIT]),
    Q6 = Var::output("q6").unit("rad").init_depends_on(&[Q_INIT]),
    Q7 = Var::output("q7").unit("rad").init_depends_on(&[Q_INIT]),
    FINGER_WIDTH = Var::output("finger_width").unit("m").init_depends_on(&[GRIPPER_WIDTH0])
        .desc("Finger gap (each finger joint is half of it)"),
    TRACKING_ERROR_RMS = Var::output("tracking_error_rms").unit("rad").init_depends_on(&[])
        .desc("RMS joint tracking error over the current/last accepted trajectory (all joints)"),
    STATUS = Var::output_discrete("status", Start::Int32(0)).init_depends_on(TRAJECTORY_CHECK)
        .desc("0 ok (idle or done), 1 executing, 2 last trajectory rejected"),
    JOINT_STATES = Var::output_discrete("joint_states", Start::Binary(&[])).mime(JointState::MIME_TYPE).max_size(agrisim_fmi::port::frames_max_size(4096, 1024))
        .init_depends_on(&[SIDE, Q_INIT, GRIPPER_WIDTH0, POSITION_NOISE, SEED, Var::TIME])
        .desc("sensor_msgs/JointState: 7 arm joints + 2 finger joints, position/velocity/effort (CDR frames of the last port_window)"),
    JOINT_STATES_SEQ = Var::output_discrete("joint_states_seq", Start::Int64(0)).init_depends_on(&[]),
    TRAJECTORY_STATUS = Var::output_discrete("trajectory_status", Start::Binary(&[])).mime(TrajectoryStatus::MIME_TYPE)
        .max_size(agrisim_fmi::port::frames_max_size(4096, 1024)).init_depends_on(&[SIDE, Q_INIT, TRAJECTORY, TRAJECTORY_SEQ, Var::TIME])
        .desc("agrisim_msgs/TrajectoryStatus, on change and at status_rate"),
    TRAJECTORY_STATUS_SEQ = Var::output_discrete("trajectory_status_seq", Start::Int64(0)).init_depends_on(&[]),
    GRIPPER_STATE = Var::output_discrete("gripper_state", Start::Binary(&[])).mime(GripperState::MIME_TYPE).max_size(agrisim_fmi::port::frames_max_size(1024, 1024))
        .init_depends_on(&[SIDE, GRIPPER_WIDTH0, GRIPPER_COMMAND, GRIPPER_COMMAND_SEQ, Var::TIME])
        .desc("agrisim_msgs/GripperState, with joint_states"),
    GRIPPER_STATE_SEQ = Var::output_discrete("gripper_state_seq", Start::Int64(0)).init_depends_on(&[]),
    // --- appended: earlier value references stay as they were ---
    MAX_GRIP_FORCE = Var::param("max_grip_force", Start::Float64(70.0)).unit("N").range(0.0, 1000.0)
        .desc("Force limit of the gripper: a command's max_effort is capped here (Franka Hand datasheet: continuous grasping force 70 N)"),
    LOAD_FX = Var::input("load_fx", 0.0).unit("N")
        .desc("Force a held load exerts on the hand, in {side}_link0 (world FMU: a fruit still on its plant); turned into joint torques"),
    LOAD_FY = Var::input("load_fy", 0.0).unit("N"),
    LOAD_FZ = Var::input("load_fz", 0.0).unit("N"),
    LOAD_MX = Var::input("load_mx", 0.0).unit("N.m").desc("Moment of that load about the origin of {side}_link0, in {side}_link0"),
    LOAD_MY = Var::input("load_my", 0.0).unit("N.m"),
    LOAD_MZ = Var::input("load_mz", 0.0).unit("N.m"),
    GRIP_FORCE = Var::output("grip_force").unit("N").init_depends_on(&[])
        .desc("Force the fingers squeeze with (0 unless stalled on an object): the gripper's measured force"),
}}

/// The load inputs (force then moment).
pub const LOAD: [usize; 6] = [LOAD_FX, LOAD_FY, LOAD_FZ, LOAD_MX, LOAD_MY, LOAD_MZ];

/// What accepting or rejecting a trajectory present at initialization depends on.
const TRAJECTORY_CHECK: &[usize] = &[SIDE, Q_INIT, TRAJECTORY, TRAJECTORY_SEQ];

/// The joint position outputs in joint order.
pub const Q: [usize; 7] = [Q1, Q2, Q3, Q4, Q5, Q6, Q7];
