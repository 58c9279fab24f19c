//! The JointStateFromScalars variable table.

use agrisim_fmi::{Start, Var};
use agrisim_msgs::sensor_msgs::JointState;

/// Most joints one instance reports (inputs q1..q7).
pub const N: usize = 7;

agrisim_fmi::variables! { pub VARIABLES {
    JOINTS = Var::param("joints", Start::String("left_joint1,left_joint2,left_joint3,left_joint4,left_joint5,left_joint6,left_joint7"))
        .desc("Comma-separated joint names (1 to 7): input qk is reported under the k-th name"),
    RATE = Var::param("rate", Start::Float64(50.0)).unit("Hz").range(0.001, 1000.0)
        .desc("Publication rate of joint_states, scheduled on simulation time"),
    WITH_VELOCITY = Var::param("with_velocity", Start::Boolean(false))
        .desc("Report qd1..qd7 as the velocity array (false: velocity left empty, as for a model without velocity outputs)"),
    PORT_WINDOW = agrisim_fmi::port_window(),
    Q1 = Var::input("q1", 0.0).unit("rad").desc("Position of the first joint in joints"),
    Q2 = Var::input("q2", 0.0).unit("rad"),
    Q3 = Var::input("q3", 0.0).unit("rad"),
    Q4 = Var::input("q4", 0.0).unit("rad"),
    Q5 = Var::input("q5", 0.0).unit("rad"),
    Q6 = Var::input("q6", 0.0).unit("rad"),
    Q7 = Var::input("q7", 0.0).unit("rad"),
    QD1 = Var::input("qd1", 0.0).unit("rad/s").desc("Velocity of the first joint in joints (used when with_velocity)"),
    QD2 = Var::input("qd2", 0.0).unit("rad/s"),
    QD3 = Var::input("qd3", 0.0).unit("rad/s"),
    QD4 = Var::input("qd4", 0.0).unit("rad/s"),
    QD5 = Var::input("qd5", 0.0).unit("rad/s"),
    QD6 = Var::input("qd6", 0.0).unit("rad/s"),
    QD7 = Var::input("qd7", 0.0).unit("rad/s"),
    JOINT_STATES = Var::output_discrete("joint_states", Start::Binary(&[])).mime(JointState::MIME_TYPE).max_size(agrisim_fmi::port::frames_max_size(4096, 1024))
        .init_depends_on(&[JOINTS, RATE, WITH_VELOCITY, PORT_WINDOW, Q1, Q2, Q3, Q4, Q5, Q6, Q7, QD1, QD2, QD3, QD4, QD5, QD6, QD7, Var::TIME])
        .desc("sensor_msgs/JointState of the configured joints at rate (CDR frames of the last port_window)"),
    JOINT_STATES_SEQ = Var::output_discrete("joint_states_seq", Start::Int64(0)).init_depends_on(&[RATE, Var::TIME])
        .desc("Sequence number of the newest message in joint_states"),
}}

/// The position and velocity inputs, in joint order.
pub const Q: [usize; N] = [Q1, Q2, Q3, Q4, Q5, Q6, Q7];
pub const QD: [usize; N] = [QD1, QD2, QD3, QD4, QD5, QD6, QD7];
