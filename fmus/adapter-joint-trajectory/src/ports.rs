//! The JointTrajectoryToScalars variable table.

use agrisim_fmi::{Start, Var};
use agrisim_msgs::trajectory_msgs::JointTrajectory;

/// Most joints one instance drives (outputs q1..q7).
pub const N: usize = 7;

agrisim_fmi::variables! { pub VARIABLES {
    JOINTS = Var::param("joints", Start::String("left_joint1,left_joint2,left_joint3,left_joint4,left_joint5,left_joint6,left_joint7"))
        .desc("Comma-separated joint names (1 to 7): the k-th drives output qk; a trajectory must name exactly these, in any order"),
    Q1_INIT = Var::param("q1_init", Start::Float64(0.0)).unit("rad").desc("Set-point q1 before any trajectory"),
    Q2_INIT = Var::param("q2_init", Start::Float64(0.0)).unit("rad"),
    Q3_INIT = Var::param("q3_init", Start::Float64(0.0)).unit("rad"),
    Q4_INIT = Var::param("q4_init", Start::Float64(0.0)).unit("rad"),
    Q5_INIT = Var::param("q5_init", Start::Float64(0.0)).unit("rad"),
    Q6_INIT = Var::param("q6_init", Start::Float64(0.0)).unit("rad"),
    Q7_INIT = Var::param("q7_init", Start::Float64(0.0)).unit("rad"),
    TRAJECTORY = Var::input_discrete("trajectory", Start::Binary(&[])).mime(JointTrajectory::MIME_TYPE).max_size(16 << 20)
        .desc("trajectory_msgs/JointTrajectory (CDR frames, or one bare CDR message); those after the last taken are taken in order, each replacing the one before"),
    TRAJECTORY_SEQ = Var::input_discrete("trajectory_seq", Start::Int64(0)).desc("Sequence number of the newest message in trajectory"),
    Q1 = Var::output("q1").unit("rad").init_depends_on(INIT).desc("Set-point of the first joint in joints"),
    Q2 = Var::output("q2").unit("rad").init_depends_on(INIT),
    Q3 = Var::output("q3").unit("rad").init_depends_on(INIT),
    Q4 = Var::output("q4").unit("rad").init_depends_on(INIT),
    Q5 = Var::output("q5").unit("rad").init_depends_on(INIT),
    Q6 = Var::output("q6").unit("rad").init_depends_on(INIT),
    Q7 = Var::output("q7").unit("rad").init_depends_on(INIT),
    STATUS = Var::output_discrete("status", Start::Int32(0)).init_depends_on(INIT)
        .desc("0 holding (no trajectory, or past its end), 1 executing, 2 the last trajectory was rejected (see the log)"),
    COUNT = Var::output_discrete("count", Start::Int32(0)).init_depends_on(INIT).desc("Trajectories accepted"),
}}

/// A trajectory present at initialization is taken then (its first point may be at time 0).
const INIT: &[usize] =
    &[JOINTS, Q1_INIT, Q2_INIT, Q3_INIT, Q4_INIT, Q5_INIT, Q6_INIT, Q7_INIT, TRAJECTORY, TRAJECTORY_SEQ, Var::TIME];

/// The set-point outputs and their initial values, in joint order.
pub const Q: [usize; N] = [Q1, Q2, Q3, Q4, Q5, Q6, Q7];
pub const Q_INIT: [usize; N] = [Q1_INIT, Q2_INIT, Q3_INIT, Q4_INIT, Q5_INIT, Q6_INIT, Q7_INIT];

/// `status` values.
pub mod status {
    pub const HOLDING: i32 = 0;
    pub const EXECUTING: i32 = 1;
    pub const REJECTED: i32 = 2;
}
