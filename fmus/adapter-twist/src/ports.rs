//! The variable table: the fixed part (parameter, message port, counters) followed by one
//! Float64 output per generated message field, assembled in const context so the table stays
//! a plain `&'static [Var]` whose value references follow the .msg field order.

use crate::fields::{FIELDS, N};
use agrisim_fmi::{Start, Var};
use agrisim_msgs::geometry_msgs::Twist;

agrisim_fmi::variables! { pub FIXED {
    TIMEOUT = Var::tunable("timeout", Start::Float64(0.5)).unit("s")
        .desc("Outputs go to 0 when no fresh command arrived for this long (like the chassis's cmd_timeout); <= 0 disables the watchdog"),
    CMD_VEL = Var::input_discrete("cmd_vel", Start::Binary(&[])).mime(Twist::MIME_TYPE).max_size(agrisim_fmi::port::frames_max_size(1024, 64))
        .desc("Velocity commands (geometry_msgs/Twist, CDR frames, or one bare CDR message); those after the last taken are applied in order"),
    CMD_VEL_SEQ = Var::input_discrete("cmd_vel_seq", Start::Int64(0)).desc("Sequence number of the newest command in cmd_vel"),
    COUNT = Var::output_discrete("count", Start::Int32(0)).init_depends_on(COMMAND)
        .desc("Valid commands taken since initialization"),
    ACTIVE = Var::output_discrete("active", Start::Boolean(false)).init_depends_on(COMMAND)
        .desc("A command was taken and the watchdog has not expired (false: the outputs are 0)"),
}}

/// What the outputs' initial values depend on: a command present at initialization is taken.
const COMMAND: &[usize] = &[CMD_VEL, CMD_VEL_SEQ];

/// Index of the first field output; field `k` of [`FIELDS`] is at `FIRST_FIELD + k`.
pub const FIRST_FIELD: usize = FIXED.len();

/// The whole table: [`FIXED`] then the field outputs.
pub const VARIABLES: &[Var] = &table();

const fn table() -> [Var; FIRST_FIELD + N] {
    let mut t = [FIXED[0]; FIRST_FIELD + N];
    let mut i = 0;
    while i < FIRST_FIELD {
        t[i] = FIXED[i];
        i += 1;
    }
    let mut k = 0;
    while k < N {
        t[FIRST_FIELD + k] =
            Var::output(FIELDS[k].name).unit(FIELDS[k].unit).init_depends_on(COMMAND).desc(FIELDS[k].desc);
        k += 1;
    }
    t
}
