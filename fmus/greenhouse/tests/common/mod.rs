//! What the tests that drive the robot's left hand through the crop share: the robot placed
//! so that its hand is under a point, and the inputs that hold it there.

use agrisim_fmi::Store;
use agrisim_fmu_greenhouse::ports::*;
use agrisim_fmu_greenhouse::robot_model::{Coords, RobotModel, Side};
use agrisim_msgs::agrisim::MovedObjects;
use agrisim_msgs::Message;
use agrisim_scene::scene::Object;

pub const LEFT_Q: [usize; 7] = [LEFT_Q1, LEFT_Q2, LEFT_Q3, LEFT_Q4, LEFT_Q5, LEFT_Q6, LEFT_Q7];
pub const RIGHT_Q: [usize; 7] = [RIGHT_Q1, RIGHT_Q2, RIGHT_Q3, RIGHT_Q4, RIGHT_Q5, RIGHT_Q6, RIGHT_Q7];

/// The objects of the scene `toml` as the world FMU grows them.
pub fn objects(toml: &str) -> Vec<Object> {
    let cfg = agrisim_scene::config::GreenhouseConfig::from_toml_str(toml).unwrap();
    agrisim_scene::generate(&cfg, cfg.seed).objects
}

/// The left TCP (base frame) at coordinates `c`.
pub fn tcp(model: &RobotModel, c: &Coords) -> [f64; 3] {
    let mut out = Vec::new();
    model.fk(c, &mut out);
    out[model.link_index("left_hand_tcp").unwrap()].trans
}

pub fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// The base pose (x, y, yaw: facing -y) and lift that put the left TCP, at the default arm
/// pose, `below` m under point `p`.
pub fn under(model: &RobotModel, p: [f64; 3], below: f64) -> ([f64; 3], f64) {
    let c0 = Coords::default();
    let lift = p[2] - below - tcp(model, &c0)[2];
    let t = tcp(model, &Coords { lift, ..c0 });
    let yaw = -std::f64::consts::FRAC_PI_2;
    let (s, co) = yaw.sin_cos();
    ([p[0] - (co * t[0] - s * t[1]), p[1] - (s * t[0] + co * t[1]), yaw], lift)
}

/// Holds the base at `planar`, the lift at `lift` and both arms at their default pose.
pub fn drive(io: &mut Store, planar: [f64; 3], lift: f64) {
    io.set_f64(BASE_X, planar[0]);
    io.set_f64(BASE_Y, planar[1]);
    io.set_f64(BASE_YAW, planar[2]);
    io.set_f64(LIFT_POSITION, lift);
    let c = Coords::default();
    for (i, vr) in LEFT_Q.into_iter().enumerate() {
        io.set_f64(vr, c.arms[Side::Left as usize][i]);
    }
    for (i, vr) in RIGHT_Q.into_iter().enumerate() {
        io.set_f64(vr, c.arms[Side::Right as usize][i]);
    }
}

/// The lift at time `t` of a sweep from `lift0`: up `rise` m at 0.2 m/s, down again, then
/// still.
pub fn sweep(lift0: f64, t: f64, rise: f64) -> f64 {
    let up = rise / 0.2;
    lift0
        + 0.2
            * if t < up {
                t
            } else if t < 2.0 * up {
                2.0 * up - t
            } else {
                0.0
            }
}

/// The world's `moved_objects` as of this step: a message comes only with a change (the port
/// keeps it for its window), so without one it is still `before`.
pub fn moved_now(io: &Store, before: &MovedObjects) -> MovedObjects {
    let newest = agrisim_fmi::port::latest(io, MOVED_OBJECTS);
    if newest.is_empty() {
        before.clone()
    } else {
        MovedObjects::from_cdr(newest).unwrap()
    }
}
