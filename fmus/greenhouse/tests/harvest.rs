//! Harvest physics through the Model trait: grasp, carry, place, drop, free fall, handover,
//! arm-arm, arm-wall and carried-fruit-wall contacts, planning scene, determinism. Joint
//! values come from a small numeric IK (damped least squares on the world's own FK, written
//! here) so the hands really reach the fruit and the box the way an arm FMU would put them there.

#![allow(clippy::needless_range_loop)] // small dense linear algebra reads best with indices

use agrisim_fmi::{Model, Quiet, Store, Value};
use agrisim_fmu_greenhouse::ports::*;
use agrisim_fmu_greenhouse::robot_links::from_rapier;
use agrisim_fmu_greenhouse::robot_model::{Coords, RobotModel, Side, READY_POSE};
use agrisim_fmu_greenhouse::GreenhouseWorld;
use agrisim_msgs::agrisim::{CollisionState, PlantDamage};
use agrisim_msgs::Message;
use agrisim_robot::Pose as RPose;

const H: f64 = 0.02;
const G: f64 = 9.81;

/// Two short rows, one fruit per truss, no leaves: fruit well apart from each other.
const SCENE: &str = "rows = 2\nactive_rows = 2\nwidth = 12.0\nlength = 20.0\nrow_length = 8.0\nleaf_density = 0\nfruit_per_truss = 1\ntrusses_per_plant = 2";

const LEFT_Q: [usize; 7] = [LEFT_Q1, LEFT_Q2, LEFT_Q3, LEFT_Q4, LEFT_Q5, LEFT_Q6, LEFT_Q7];
const RIGHT_Q: [usize; 7] = [RIGHT_Q1, RIGHT_Q2, RIGHT_Q3, RIGHT_Q4, RIGHT_Q5, RIGHT_Q6, RIGHT_Q7];

fn q_vrs(side: Side) -> [usize; 7] {
    match side {
        Side::Left => LEFT_Q,
        Side::Right => RIGHT_Q,
    }
}

fn width_vr(side: Side) -> usize {
    match side {
        Side::Left => LEFT_FINGER_WIDTH,
        Side::Right => RIGHT_FINGER_WIDTH,
    }
}

/// Link pose in base_link for `c`.
fn link_in_base(model: &RobotModel, c: &Coords, link: &str) -> RPose {
    let mut out = Vec::new();
    model.fk(c, &mut out);
    out[model.link_index(link).unwrap()]
}

fn tcp_name(side: Side) -> String {
    format!("{}_hand_tcp", side.prefix())
}

/// Solves 6x6 (or smaller) `a x = b` by Gaussian elimination with partial pivoting.
fn solve(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Vec<f64> {
    let n = b.len();
    for k in 0..n {
        let p = (k..n).max_by(|&i, &j| a[i][k].abs().total_cmp(&a[j][k].abs())).unwrap();
        a.swap(k, p);
        b.swap(k, p);
        for i in k + 1..n {
            let f = a[i][k] / a[k][k];
            for j in k..n {
                a[i][j] -= f * a[k][j];
            }
            b[i] -= f * b[k];
        }
    }
    let mut x = vec![0.0; n];
    for k in (0..n).rev() {
        x[k] = (b[k] - (k + 1..n).map(|j| a[k][j] * x[j]).sum::<f64>()) / a[k][k];
    }
    x
}

/// Joint values of `side`'s arm putting its TCP at `target` (base_link frame) with the hand's
/// approach axis (z) along `approach`; starts from `c`. Damped least squares, finite-difference
/// Jacobian, joint limits enforced. Panics when it does not converge (the test's geometry is wrong).
fn ik(model: &RobotModel, c: &Coords, side: Side, target: [f64; 3], approach: [f64; 3]) -> [f64; 7] {
    let s = side as usize;
    let residual = |c: &Coords| {
        let p = link_in_base(model, c, &tcp_name(side));
        let z = p.axis(2);
        let w = 0.3; // orientation weight [m/rad-ish]
        let mut e = vec![target[0] - p.trans[0], target[1] - p.trans[1], target[2] - p.trans[2]];
        e.extend((0..3).map(|i| w * (approach[i] - z[i])));
        e
    };
    let mut cur = *c;
    for _ in 0..500 {
        let e = residual(&cur);
        if e.iter().map(|v| v * v).sum::<f64>().sqrt() < 1e-7 {
            return cur.arms[s];
        }
        let mut jac = vec![vec![0.0; 7]; 6];
        for j in 0..7 {
            let mut d = cur;
            d.arms[s][j] += 1e-6;
            let ed = residual(&d);
            for i in 0..6 {
                jac[i][j] = -(ed[i] - e[i]) / 1e-6;
            }
        }
        let lambda2 = 1e-4;
        let jjt: Vec<Vec<f64>> = (0..6)
            .map(|i| {
                (0..6)
                    .map(|k| (0..7).map(|j| jac[i][j] * jac[k][j]).sum::<f64>() + if i == k { lambda2 } else { 0.0 })
                    .collect()
            })
            .collect();
        let y = solve(jjt, e.clone());
        for j in 0..7 {
            let dq: f64 = (0..6).map(|i| jac[i][j] * y[i]).sum();
            let (lo, hi) = model.arm_limits[s][j];
            cur.arms[s][j] = (cur.arms[s][j] + dq.clamp(-0.2, 0.2)).clamp(lo + 1e-3, hi - 1e-3);
        }
    }
    let e = residual(&cur);
    panic!("IK for {side:?} to {target:?} did not converge: residual {e:?}");
}

struct Sim {
    m: GreenhouseWorld,
    io: Store,
    t: f64,
    model: RobotModel,
}

impl Sim {
    fn start(planar: [f64; 3], c: &Coords) -> Sim {
        let mut io = Store::new(GreenhouseWorld::VARIABLES);
        *io.value_mut(SCENE_VAR) = Value::String(SCENE.to_string());
        let mut s = Sim { m: GreenhouseWorld::new(), io, t: 0.0, model: RobotModel::load().unwrap() };
        s.set(planar, c);
        s.m.initialize(&mut s.io, 0.0, &mut Quiet).unwrap();
        s
    }

    fn set(&mut self, [x, y, yaw]: [f64; 3], c: &Coords) {
        self.io.set_f64(BASE_X, x);
        self.io.set_f64(BASE_Y, y);
        self.io.set_f64(BASE_YAW, yaw);
        self.io.set_f64(LIFT_POSITION, c.lift);
        for side in Side::BOTH {
            for (i, vr) in q_vrs(side).into_iter().enumerate() {
                self.io.set_f64(vr, c.arms[side as usize][i]);
            }
            self.io.set_f64(width_vr(side), c.widths[side as usize]);
        }
    }

    fn step(&mut self) {
        self.m.do_step(&mut self.io, self.t, H, &mut Quiet).unwrap();
        self.t += H;
    }

    fn planar(&self) -> [f64; 3] {
        [self.io.f64(BASE_X), self.io.f64(BASE_Y), self.io.f64(BASE_YAW)]
    }

    /// Map-frame pose of `link` for the current inputs.
    fn link_in_map(&self, c: &Coords, link: &str) -> RPose {
        let [x, y, yaw] = self.planar();
        agrisim_fmu_greenhouse::robot_links::base_pose(x, y, yaw).mul(&link_in_base(&self.model, c, link))
    }

    fn fruit_centre(&self, f: usize) -> [f64; 3] {
        from_rapier(&self.m.scene().unwrap().fruit_pose(f)).trans
    }

    fn fruit_id(&self, f: usize) -> i32 {
        let w = self.m.scene().unwrap();
        w.objects[w.fruit[f].object].id as i32
    }

    fn diameter(&self, f: usize) -> f64 {
        2.0 * self.m.scene().unwrap().fruit[f].radius
    }

    fn collision_state(&self) -> CollisionState {
        CollisionState::from_cdr(agrisim_fmi::port::latest(&self.io, COLLISION_STATE)).unwrap()
    }
}

use agrisim_fmu_greenhouse::ports::SCENE as SCENE_VAR;

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// The scene's fruit centres and radii (same generator and seed as the FMU).
fn fruit_list() -> Vec<([f64; 3], f64)> {
    let cfg = agrisim_scene::config::GreenhouseConfig::from_toml_str(SCENE).unwrap();
    let gh = agrisim_scene::generate(&cfg, cfg.seed);
    gh.objects
        .iter()
        .filter_map(|o| match o.shape {
            agrisim_scene::Shape::Sphere { radius } => Some((o.placement.translation, radius)),
            _ => None,
        })
        .collect()
}

/// The first fruit past x = 8 m at a height the lift reaches with the arm's ready pose, and
/// the base pose + lift putting `side`'s TCP (ready pose, hand pointing down) on its centre.
/// The robot faces -y; its body may overlap the row (irrelevant here: robot parts are kinematic).
fn grasp_setup(side: Side) -> (usize, [f64; 3], Coords) {
    grasp_setup_nth(side, 0)
}

/// Like [`grasp_setup`] for the `nth` such fruit.
fn grasp_setup_nth(side: Side, nth: usize) -> (usize, [f64; 3], Coords) {
    let model = RobotModel::load().unwrap();
    let c0 = Coords::default();
    let tcp0 = link_in_base(&model, &c0, &tcp_name(side));
    let fruit = fruit_list();
    let (f, (p, _)) = fruit
        .iter()
        .enumerate()
        .filter(|(_, (p, _))| p[2] > tcp0.trans[2] + 0.1 && p[2] < tcp0.trans[2] + 0.7 && p[0] > 8.0)
        .nth(nth)
        .expect("a fruit in the lift's range");
    let lift = p[2] - tcp0.trans[2];
    let c = Coords { lift, ..c0 };
    let tcp = link_in_base(&model, &c, &tcp_name(side)).trans;
    let yaw = -std::f64::consts::FRAC_PI_2;
    let (s, co) = yaw.sin_cos();
    // map = base + R(yaw) tcp
    let planar = [p[0] - (co * tcp[0] - s * tcp[1]), p[1] - (s * tcp[0] + co * tcp[1]), yaw];
    (f, planar, c)
}

/// Left-arm joints (lift 0.45) holding the TCP 12 cm above the box interior's top, hand down.
fn over_the_box(model: &RobotModel, c: &Coords) -> Coords {
    let box_link = link_in_base(model, c, "harvest_box_link");
    let above = [box_link.trans[0], box_link.trans[1] + 0.05, box_link.trans[2] + model.box_interior.hi[2] + 0.12];
    let mut over = *c;
    over.lift = 0.45;
    over.arms[0] = ik(model, &over, Side::Left, above, [0.0, 0.0, -1.0]);
    over
}

/// Closes `side`'s gripper from its current width to 0 in 1 cm steps; returns the width at
/// which the fruit was reported held (None if never).
fn close(sim: &mut Sim, c: &mut Coords, side: Side) -> Option<f64> {
    let s = side as usize;
    let planar = sim.planar();
    let mut held_at = None;
    while c.widths[s] > 0.0 {
        c.widths[s] = (c.widths[s] - 0.01).max(0.0);
        sim.set(planar, c);
        sim.step();
        let id = sim.io.i32(if side == Side::Left { LEFT_HELD_ID } else { RIGHT_HELD_ID });
        if id >= 0 && held_at.is_none() {
            held_at = Some(c.widths[s]);
        }
    }
    held_at
}

/// Opens the left gripper fully at `c` (the fruit it holds is released); returns the inputs
/// now applied.
fn open_left(sim: &mut Sim, planar: [f64; 3], c: &Coords) -> Coords {
    let mut open = *c;
    open.widths[0] = 0.08;
    sim.set(planar, &open);
    open
}

/// Steps until the counter output `counter` is non-zero or `max` steps have passed, calling
/// `each` with the step number after every step; returns the steps taken.
fn step_until(sim: &mut Sim, counter: usize, max: usize, mut each: impl FnMut(&Sim, usize)) -> usize {
    let mut steps = 0;
    while sim.io.i32(counter) == 0 && steps < max {
        sim.step();
        steps += 1;
        each(sim, steps);
    }
    steps
}

/// Moves the inputs linearly from `a` to `b` over `n` steps.
fn glide(sim: &mut Sim, planar: [f64; 3], a: &Coords, b: &Coords, n: usize, mut each: impl FnMut(&Sim, &Coords)) {
    for k in 1..=n {
        let f = k as f64 / n as f64;
        let mut c = *a;
        c.lift = a.lift + f * (b.lift - a.lift);
        for s in 0..2 {
            for j in 0..7 {
                c.arms[s][j] = a.arms[s][j] + f * (b.arms[s][j] - a.arms[s][j]);
            }
        }
        sim.set(planar, &c);
        sim.step();
        each(sim, &c);
    }
}

/// The PlantDamage message the world published in the last step, if any.
fn newest_damage(sim: &Sim) -> Option<PlantDamage> {
    let b = agrisim_fmi::port::latest(&sim.io, PLANT_DAMAGE);
    (!b.is_empty()).then(|| PlantDamage::from_cdr(b).unwrap())
}

#[test]
fn grasp_carry_and_place_in_the_box() {
    let (f, planar, c0) = grasp_setup(Side::Left);
    let mut sim = Sim::start(planar, &c0);
    let tcp = sim.link_in_map(&c0, "left_hand_tcp").trans;
    assert!(dist(tcp, sim.fruit_centre(f)) < 1e-6, "setup: TCP {tcp:?} on the fruit {:?}", sim.fruit_centre(f));
    assert_eq!((sim.io.i32(LEFT_HELD_ID), sim.io.f64(LEFT_GRASP_WIDTH), sim.io.i32(PICKED_COUNT)), (-1, 0.0, 0));
    let d = sim.diameter(f);
    let mut c = c0;
    let held_at = close(&mut sim, &mut c, Side::Left).expect("the closing gripper holds the fruit");
    assert!(held_at <= d + 0.003 && held_at > d - 0.01 - 1e-9, "held at gap {held_at}, diameter {d}");
    assert_eq!(sim.io.i32(LEFT_HELD_ID), sim.fruit_id(f));
    assert_eq!(sim.io.f64(LEFT_GRASP_WIDTH), d);
    assert_eq!((sim.io.i32(RIGHT_HELD_ID), sim.io.f64(RIGHT_GRASP_WIDTH)), (-1, 0.0));
    assert_eq!(sim.io.i32(PICKED_COUNT), 0, "held, still on its plant");

    // Carry it over the box: lift up, arm to a pose above the box interior, the fruit on the TCP.
    let model = RobotModel::load().unwrap();
    let interior = model.box_interior;
    let over = over_the_box(&model, &c);
    let start = sim.fruit_centre(f);
    let mut worst: f64 = 0.0;
    let mut damage = None;
    glide(&mut sim, planar, &c, &over, 60, |sim, c| {
        worst = worst.max(dist(sim.link_in_map(c, "left_hand_tcp").trans, sim.fruit_centre(f)));
        damage = newest_damage(sim).or(damage.take());
    });
    assert!(worst < 1e-4, "the fruit follows the TCP (worst offset {worst} m)");
    assert!(dist(start, sim.fruit_centre(f)) > 0.5, "it moved");
    assert_eq!(sim.io.i32(PICKED_COUNT), 1, "carried away, its pedicel broke");
    // /plant_damage says the same as the scalar outputs: one break, its mode, force, moment.
    let pd = damage.take().expect("a PlantDamage message on the break");
    let breaks = [pd.detached_by_pull, pd.detached_by_bend, pd.detached_by_twist];
    assert_eq!(breaks.iter().sum::<u32>(), 1, "{pd:?}");
    let mode = ["pull", "bend", "twist"][breaks.iter().position(|&b| b == 1).unwrap()];
    assert_eq!(pd.last_detach_mode, mode);
    assert_eq!(sim.io.i32(LAST_DETACH_MODE), breaks.iter().position(|&b| b == 1).unwrap() as i32 + 1);
    assert_eq!(
        (pd.last_detach_force, pd.last_detach_moment),
        (sim.io.f64(LAST_DETACH_FORCE), sim.io.f64(LAST_DETACH_MOMENT))
    );
    assert!(pd.last_detach_force > 0.0 && pd.header.frame_id == "map");
    let c = over;

    // Open: it falls into the box and is placed.
    let open = open_left(&mut sim, planar, &c);
    let steps = step_until(&mut sim, PLACED_COUNT, 150, |sim, steps| {
        damage = newest_damage(sim).or(damage.take());
        if steps == 1 {
            assert_eq!((sim.io.i32(LEFT_HELD_ID), sim.io.f64(LEFT_GRASP_WIDTH)), (-1, 0.0), "released");
        }
    });
    assert_eq!(sim.io.i32(PLACED_COUNT), 1, "placed within 3 s");
    assert_eq!(sim.io.i32(LAST_PLACED_ID), sim.fruit_id(f));
    assert_eq!(sim.io.i32(DROPPED_COUNT), 0);
    let pd = damage.unwrap_or(pd);
    assert_eq!(
        (pd.bruised_by_grip, pd.bruised_by_impact, pd.unripe_detached, pd.stems_broken),
        (
            sim.io.i32(GRIP_BRUISED_COUNT) as u32,
            sim.io.i32(IMPACT_BRUISED_COUNT) as u32,
            sim.io.i32(UNRIPE_DETACHED_COUNT) as u32,
            0
        )
    );
    let box_now = sim.link_in_map(&open, "harvest_box_link");
    let in_box = box_now.inverse().transform_point(sim.fruit_centre(f));
    let r = d / 2.0;
    assert!(interior.contains(in_box), "{in_box:?}");
    assert!((in_box[2] - (interior.lo[2] + r)).abs() < 0.01, "rests on the bottom: {in_box:?}, r {r}");
    // Falling ~0.3 m takes ~0.25 s, then 0.2 s of rest.
    assert!(steps > 15 && steps < 60, "placed after {steps} steps");

    // The box carries it: drive 1 m along +x... the fruit keeps its place in the box.
    let moved = [planar[0] + 1.0, planar[1] + 0.3, planar[2] + 0.2];
    for k in 1..=20 {
        let f_ = k as f64 / 20.0;
        sim.set(std::array::from_fn(|i| planar[i] + f_ * (moved[i] - planar[i])), &open);
        sim.step();
    }
    let box_now = sim.link_in_map(&open, "harvest_box_link");
    let in_box2 = box_now.inverse().transform_point(sim.fruit_centre(f));
    assert!(dist(in_box, in_box2) < 1e-4, "{in_box:?} -> {in_box2:?}");
    assert_eq!((sim.io.i32(PLACED_COUNT), sim.io.i32(PICKED_COUNT)), (1, 1));
    // The sensors are told: moved_objects lists the boxed fruit where it is now (and, in
    // this scene without leaves in reach, nothing else).
    let moved = agrisim_msgs::agrisim::MovedObjects::from_cdr(agrisim_fmi::port::latest(&sim.io, MOVED_OBJECTS))
        .expect("the box moved in the last step, and the fruit with it");
    assert_eq!(moved.ids, [sim.fruit_id(f) as u32]);
    let p = &moved.poses[0].position;
    assert!(dist([p.x, p.y, p.z], sim.fruit_centre(f)) < 1e-6, "{p:?}");
}

#[test]
fn released_elsewhere_falls_to_the_floor_in_the_analytic_time() {
    let (f, planar, c0) = grasp_setup(Side::Left);
    let mut sim = Sim::start(planar, &c0);
    let mut c = c0;
    close(&mut sim, &mut c, Side::Left).expect("held");
    // Swing the hand out to the robot's left (over the aisle floor, nothing below it).
    let model = RobotModel::load().unwrap();
    let mut out = c;
    out.lift = 0.3;
    out.arms[0] = ik(&model, &out, Side::Left, [0.0, 0.8, 1.1], [0.0, 0.0, -1.0]);
    glide(&mut sim, planar, &c, &out, 40, |_, _| {});
    // Hold still for a step so the release velocity is zero.
    sim.step();
    let z0 = sim.fruit_centre(f)[2];
    let r = sim.diameter(f) / 2.0;
    open_left(&mut sim, planar, &out);
    let steps = step_until(&mut sim, DROPPED_COUNT, 200, |_, _| {});
    assert_eq!(sim.io.i32(DROPPED_COUNT), 1);
    assert_eq!(sim.io.i32(PLACED_COUNT), 0);
    let fall = z0 - r - 0.005; // landing = lowest point within 5 mm of the floor
    let analytic = (2.0 * fall / G).sqrt();
    let measured = steps as f64 * H;
    assert!(
        (measured - analytic).abs() <= 2.0 * H + 1e-9,
        "fell {fall:.3} m in {measured:.3} s, analytic {analytic:.3} s"
    );
    let p = sim.fruit_centre(f);
    assert!(p[2] - r < 0.01 && p[2] - r > -0.01, "on the floor: {p:?}");
    // It stays there (frozen) while time passes.
    for _ in 0..10 {
        sim.step();
    }
    assert!(dist(p, sim.fruit_centre(f)) < 1e-9);
}

#[test]
fn closing_beside_a_fruit_or_already_closed_does_not_grasp() {
    let (f, planar, c0) = grasp_setup(Side::Left);
    // Base 3 cm off along the hand's pad-depth axis: the fruit centre is outside the pads.
    let model = RobotModel::load().unwrap();
    let hand = link_in_base(&model, &c0, "left_hand");
    let x_axis = hand.axis(0);
    let (s, co) = planar[2].sin_cos();
    let off = [co * x_axis[0] - s * x_axis[1], s * x_axis[0] + co * x_axis[1]];
    let shifted = [planar[0] + 0.03 * off[0], planar[1] + 0.03 * off[1], planar[2]];
    let mut sim = Sim::start(shifted, &c0);
    let mut c = c0;
    assert_eq!(close(&mut sim, &mut c, Side::Left), None);
    assert_eq!(sim.io.i32(PICKED_COUNT), 0);
    let _ = f;
    // On the fruit but with the fingers already closed: opening and staying closed never grasps.
    let mut closed = c0;
    closed.widths[0] = 0.0;
    let mut sim = Sim::start(planar, &closed);
    for _ in 0..5 {
        sim.step();
    }
    assert_eq!(sim.io.i32(LEFT_HELD_ID), -1);
}

#[test]
fn handover_from_left_to_right() {
    let (f, planar, c0) = grasp_setup(Side::Left);
    let mut sim = Sim::start(planar, &c0);
    let mut c = c0;
    close(&mut sim, &mut c, Side::Left).expect("held by the left");
    let d = sim.diameter(f);
    // Handover point in front of the lift, between the arms; left hand points down, the right
    // approaches horizontally from behind (+x).
    let model = RobotModel::load().unwrap();
    let mut hand = c;
    hand.lift = 0.3;
    let p = [0.65, 0.0, 1.25];
    hand.arms[0] = ik(&model, &hand, Side::Left, p, [0.0, 0.0, -1.0]);
    let mut right_open = hand;
    right_open.arms[1] = ik(&model, &hand, Side::Right, [p[0] - 0.15, p[1], p[2]], [1.0, 0.0, 0.0]);
    glide(&mut sim, planar, &c, &right_open, 40, |_, _| {});
    let mut at = right_open;
    at.arms[1] = ik(&model, &right_open, Side::Right, p, [1.0, 0.0, 0.0]);
    glide(&mut sim, planar, &right_open, &at, 15, |_, _| {});
    assert!(dist(sim.fruit_centre(f), sim.link_in_map(&at, "right_hand_tcp").trans) < 1e-4);
    let mut c = at;
    close(&mut sim, &mut c, Side::Right).expect("the right closes on the held fruit");
    let id = sim.fruit_id(f);
    assert_eq!((sim.io.i32(LEFT_HELD_ID), sim.io.i32(RIGHT_HELD_ID)), (id, id), "held by both");
    assert_eq!((sim.io.f64(LEFT_GRASP_WIDTH), sim.io.f64(RIGHT_GRASP_WIDTH)), (d, d));
    // The left opens: the right holds it alone, it does not fall.
    let before = sim.fruit_centre(f);
    c.widths[0] = 0.08;
    sim.set(planar, &c);
    for _ in 0..10 {
        sim.step();
    }
    assert_eq!((sim.io.i32(LEFT_HELD_ID), sim.io.i32(RIGHT_HELD_ID)), (-1, id));
    assert_eq!((sim.io.f64(LEFT_GRASP_WIDTH), sim.io.f64(RIGHT_GRASP_WIDTH)), (0.0, d));
    assert!(dist(before, sim.fruit_centre(f)) < 1e-5, "not falling");
    // It follows the right hand now.
    let mut away = c;
    away.arms[1][0] -= 0.4;
    let mut worst: f64 = 0.0;
    glide(&mut sim, planar, &c, &away, 20, |sim, c| {
        worst = worst.max(dist(sim.link_in_map(c, "right_hand_tcp").trans, sim.fruit_centre(f)));
    });
    assert!(worst < 1e-4, "{worst}");
    assert_eq!((sim.io.i32(PICKED_COUNT), sim.io.i32(DROPPED_COUNT), sim.io.i32(PLACED_COUNT)), (1, 0, 0));
}

#[test]
fn arms_driven_into_each_other_report_arm_arm_contact() {
    // In the headland, nothing near.
    let planar = [2.0, 6.0, 0.0];
    let c0 = Coords::default();
    let mut sim = Sim::start(planar, &c0);
    assert!(!sim.io.bool(COLLISION), "{:?}", sim.collision_state());
    assert_eq!(sim.io.i32(CONTACT_ARM_ARM), 0);
    // Swing both arms inward about joint 1.
    let mut inward = c0;
    inward.arms[0][0] = -1.3;
    inward.arms[1][0] = 1.3;
    let mut first = None;
    glide(&mut sim, planar, &c0, &inward, 40, |sim, c| {
        if first.is_none() && sim.io.i32(CONTACT_ARM_ARM) > 0 {
            first = Some(c.arms[0][0]);
        }
    });
    let q = first.expect("the arms touch");
    assert!(q < -0.3, "first contact at q1 = {q}");
    let s = sim.collision_state();
    assert!(s.in_collision);
    let arm: Vec<_> = s.contacts.iter().filter(|c| c.object_kind == "robot_arm").collect();
    assert!(!arm.is_empty(), "{s:?}");
    for c in &arm {
        assert!(c.robot_link.starts_with("left_") && c.object_name.starts_with("right_"), "{c:?}");
        assert_eq!(c.object_id, u32::MAX);
    }
    assert_eq!((sim.io.i32(CONTACT_ROBOT_PLANT), sim.io.i32(CONTACT_ROBOT_STRUCTURE)), (0, 0));
    assert_eq!(sim.io.i32(COLLISION_COUNT), sim.io.i32(CONTACT_ARM_ARM));
}

#[test]
fn a_hand_pushed_into_the_wall_is_a_structure_contact() {
    // In the headland, 0.85 m from the front wall (its face at x = 0), facing it.
    let planar = [0.85, 6.0, std::f64::consts::PI];
    let c0 = Coords { lift: 0.4, ..Coords::default() };
    let mut sim = Sim::start(planar, &c0);
    assert!(!sim.io.bool(COLLISION));
    let model = RobotModel::load().unwrap();
    // Stretch the left arm forward (joints 2 and 4) until FK puts a finger pad tip 1 cm into the wall.
    let mut reach = c0;
    let tip = |c: &Coords| link_in_base(&model, c, "left_finger1").transform_point([0.0, 0.0075, 0.05])[0];
    while tip(&reach) < 0.86 {
        reach.arms[0][1] = (reach.arms[0][1] + 0.01).min(1.5);
        reach.arms[0][3] = (reach.arms[0][3] + 0.01).min(-0.1);
        assert!(reach.arms[0][1] < 1.5 || reach.arms[0][3] < -0.1, "the hand never reaches the wall");
    }
    let mut first = None;
    glide(&mut sim, planar, &c0, &reach, 40, |sim, c| {
        if first.is_none() && sim.io.i32(CONTACT_ROBOT_STRUCTURE) > 0 {
            first = Some(tip(c));
        }
    });
    let at = first.expect("the wall is hit");
    // Something of the hand (box, fingers: the hand is tilted) touches first, near the pad tip.
    assert!(at > 0.7 && at < 0.87, "first contact with the pad tip at {at} m from base_link (wall at 0.85 m)");
    let s = sim.collision_state();
    let wall: Vec<_> = s.contacts.iter().filter(|c| c.object_kind == "wall").collect();
    assert!(!wall.is_empty() && wall.iter().all(|c| c.robot_link.starts_with("left_")), "{s:?}");
    for c in wall {
        assert!(c.position.x.abs() < 0.02 && c.normal.x > 0.99, "contact on the wall face x = 0: {c:?}");
    }
    assert_eq!((sim.io.i32(CONTACT_ARM_ARM), sim.io.i32(CONTACT_ROBOT_PLANT)), (0, 0));
}

/// The first fruit past x = 8 m of row 1 hanging on the aisle side (y 7.0-7.2), and the base
/// pose (in the aisle, facing +x) and inputs putting the left TCP on its centre, the hand
/// approaching horizontally from the aisle (+y): the robot clear of the rows.
fn aisle_grasp_setup() -> (usize, [f64; 3], Coords) {
    let model = RobotModel::load().unwrap();
    let (f, (p, _)) = fruit_list()
        .into_iter()
        .enumerate()
        .find(|(_, (p, _))| p[0] > 8.0 && p[1] > 7.0 && p[1] < 7.2)
        .expect("a fruit on the aisle side");
    let planar = [p[0] - 0.3, 6.2, 0.0];
    // The left shoulder 0.1 m below the fruit.
    let shoulder = link_in_base(&model, &Coords::default(), "left_link1").trans[2];
    let mut c = Coords { lift: p[2] - shoulder - 0.1, ..Coords::default() };
    c.arms[0] = ik(&model, &c, Side::Left, [0.3, p[1] - planar[1], p[2]], [0.0, 1.0, 0.0]);
    (f, planar, c)
}

#[test]
fn a_carried_fruit_pushed_into_the_wall_is_a_carried_structure_contact() {
    let (f, planar, c0) = aisle_grasp_setup();
    let mut sim = Sim::start(planar, &c0);
    assert!(dist(sim.link_in_map(&c0, "left_hand_tcp").trans, sim.fruit_centre(f)) < 1e-6);
    let mut c = c0;
    close(&mut sim, &mut c, Side::Left).expect("held");
    assert_eq!(sim.io.i32(LEFT_HELD_ID), sim.fruit_id(f));
    let touched =
        |sim: &Sim| [CONTACT_ROBOT_STRUCTURE, CONTACT_ARM_ARM, CONTACT_CARRIED_STRUCTURE].map(|v| sim.io.i32(v));
    assert_eq!(touched(&sim), [0, 0, 0], "picked from among its truss: no carried contact");
    // Out of the row, the hand pointing ahead (base +x): carried through free air, nothing
    // counts (the counters are cumulative: their end values tell).
    let model = RobotModel::load().unwrap();
    let r = sim.diameter(f) / 2.0;
    let mut near = c;
    near.lift = 0.2;
    let (y, z) = (0.0, 1.3);
    near.arms[0] = ik(&model, &near, Side::Left, [0.6, y, z], [1.0, 0.0, 0.0]);
    glide(&mut sim, planar, &c, &near, 30, |_, _| {});
    assert_eq!(touched(&sim), [0, 0, 0], "{:?}", sim.collision_state());
    // To the headland, 0.85 m from the front wall (its face at x = 0), facing it: the fruit
    // sticks out past the fingertips toward it.
    let wall = [0.85, 6.0, std::f64::consts::PI];
    sim.set(wall, &near);
    sim.step();
    assert!(sim.fruit_centre(f)[0] - r > 0.2, "the fruit in free air: {:?}", sim.fruit_centre(f));
    assert!(!sim.io.bool(COLLISION), "{:?}", sim.collision_state());
    // Push 1 cm into the wall (about 0.23 m in 60 steps): the fingertips, 5 mm past the
    // fruit centre, stay clear of it.
    let mut far = near;
    far.arms[0] = ik(&model, &near, Side::Left, [0.85 - r + 0.01, y, z], [1.0, 0.0, 0.0]);
    let mut first = None;
    glide(&mut sim, wall, &near, &far, 60, |sim, _| {
        if first.is_none() && sim.io.i32(CONTACT_CARRIED_STRUCTURE) > 0 {
            first = Some(sim.fruit_centre(f)[0] - r);
        }
    });
    let front = first.expect("the carried fruit hits the wall");
    assert!(front <= 1e-4 && front > -0.01, "first contact with the fruit's front at x = {front} (wall face at 0)");
    // Held still for 0.1 s: a periodic collision_state (10 Hz) has the final depth.
    for _ in 0..5 {
        sim.step();
    }
    assert_eq!(touched(&sim), [0, 0, 1], "one onset while pressed, the robot itself touches nothing");
    assert_eq!(sim.io.i32(COLLISION_COUNT), sim.io.i32(CONTACT_ROBOT_PLANT) + 1);
    let s = sim.collision_state();
    assert!(s.in_collision && sim.io.bool(COLLISION));
    let [hit] = s.contacts.as_slice() else { panic!("one contact: {s:?}") };
    assert_eq!(
        (hit.robot_link.as_str(), hit.object_name.as_str(), hit.object_kind.as_str()),
        ("carried_fruit", "wall_xmin", "wall")
    );
    assert!(hit.position.x.abs() < 0.002 && hit.normal.x > 0.99 && (hit.depth - 0.01).abs() < 0.002, "{hit:?}");
    // Back into free air: no onset; pushed in again: a second one.
    glide(&mut sim, wall, &far, &near, 20, |_, _| {});
    assert!(!sim.io.bool(COLLISION), "{:?}", sim.collision_state());
    assert_eq!(touched(&sim), [0, 0, 1]);
    glide(&mut sim, wall, &near, &far, 20, |_, _| {});
    assert_eq!(touched(&sim), [0, 0, 2]);
    assert_eq!(sim.io.i32(LEFT_HELD_ID), sim.fruit_id(f));
}

#[test]
fn same_inputs_same_outputs_through_a_whole_harvest() {
    let run = || {
        let (_, planar, c0) = grasp_setup(Side::Left);
        let mut sim = Sim::start(planar, &c0);
        let mut c = c0;
        close(&mut sim, &mut c, Side::Left);
        let mut up = c;
        up.lift += 0.2;
        up.arms[0][0] += 0.5;
        let mut trace = vec![];
        glide(&mut sim, planar, &c, &up, 10, |sim, _| trace.push(sim.io.clone()));
        up.widths[0] = 0.08;
        sim.set(planar, &up);
        for _ in 0..60 {
            sim.step();
            trace.push(sim.io.clone());
        }
        (trace, sim.io.i32(PLACED_COUNT) + sim.io.i32(DROPPED_COUNT))
    };
    let (a, settled) = run();
    let (b, _) = run();
    assert_eq!(settled, 1, "the released fruit settled");
    assert!(a == b, "identical outputs");
}

#[test]
fn ready_pose_stays_inside_the_base_footprint() {
    // The default (unconnected) arms must not stick out of the chassis outline, or driving
    // the aisles would hit the rows with them.
    let model = RobotModel::load().unwrap();
    for side in Side::BOTH {
        for link in ["hand", "hand_tcp", "finger1", "finger2", "link7"] {
            let p = link_in_base(&model, &Coords::default(), &format!("{}_{link}", side.prefix())).trans;
            assert!(p[0].abs() < 0.6 && p[1].abs() < 0.45, "{}_{link} at {p:?}", side.prefix());
        }
    }
    assert_eq!(READY_POSE.len(), 7);
}

#[test]
fn planning_scene_lists_the_objects_near_the_robot() {
    use agrisim_msgs::agrisim::PlanningScene;
    use agrisim_msgs::shape_msgs::SolidPrimitive;
    let (f, planar, c0) = grasp_setup(Side::Left);
    let mut sim = Sim::start(planar, &c0);
    let scene = PlanningScene::from_cdr(agrisim_fmi::port::latest(&sim.io, PLANNING_SCENE)).unwrap();
    assert_eq!((sim.io.i64(PLANNING_SCENE_SEQ), scene.header.frame_id.as_str()), (1, "map"));
    // Independent selection from the generator's own objects and bounding boxes.
    let cfg = agrisim_scene::config::GreenhouseConfig::from_toml_str(SCENE).unwrap();
    let gh = agrisim_scene::generate(&cfg, cfg.seed);
    let reach = |o: &agrisim_scene::scene::Object| {
        let (lo, hi) = o.aabb();
        let dx = (lo[0] - planar[0]).max(planar[0] - hi[0]).max(0.0);
        let dy = (lo[1] - planar[1]).max(planar[1] - hi[1]).max(0.0);
        (dx * dx + dy * dy).sqrt()
    };
    let listed: std::collections::BTreeMap<String, _> = scene.objects.iter().map(|o| (o.id.clone(), o)).collect();
    assert_eq!(listed.len(), scene.objects.len(), "ids are unique");
    let (mut inside, mut checked) = (0, 0);
    for o in &gh.objects {
        let d = reach(o);
        let have = listed.get(&o.id.to_string());
        if d < 2.5 - 0.01 {
            let c = have.unwrap_or_else(|| panic!("{} at {d:.3} m missing", o.name));
            inside += 1;
            assert_eq!(c.kind, agrisim_fmu_greenhouse::collision_report::kind_label(o.kind));
            let p = c.pose.position;
            let t = o.placement.translation;
            assert!(
                (p.x - t[0]).abs() < 1e-4 && (p.y - t[1]).abs() < 1e-4 && (p.z - t[2]).abs() < 1e-4,
                "{}: {p:?} vs {t:?}",
                o.name
            );
            match o.shape {
                agrisim_scene::Shape::Sphere { radius } => {
                    assert_eq!(c.primitive.r#type, SolidPrimitive::SPHERE);
                    assert!((c.primitive.dimensions[0] - radius).abs() < 1e-6);
                }
                agrisim_scene::Shape::Cylinder { radius, half_height } => {
                    assert_eq!(c.primitive.r#type, SolidPrimitive::CYLINDER);
                    assert!(
                        (c.primitive.dimensions[0] - 2.0 * half_height).abs() < 1e-5
                            && (c.primitive.dimensions[1] - radius).abs() < 1e-6
                    );
                    // Same orientation as the scene object (cylinder axis = local z).
                    let q = c.pose.orientation;
                    let [qx, qy, qz, qw] = o.placement.rotation;
                    let dot = (q.x * qx + q.y * qy + q.z * qz + q.w * qw).abs();
                    assert!(dot > 1.0 - 1e-5, "{}: {q:?} vs {:?}", o.name, o.placement.rotation);
                }
                agrisim_scene::Shape::Box { half } => {
                    assert_eq!(c.primitive.r#type, SolidPrimitive::BOX);
                    for i in 0..3 {
                        assert!((c.primitive.dimensions[i] - 2.0 * half[i]).abs() < 1e-5);
                    }
                }
            }
            checked += 1;
        } else if d > 2.5 + 0.01 {
            assert!(have.is_none(), "{} at {d:.3} m listed", o.name);
        }
    }
    assert!(inside > 50 && checked == inside, "{inside} objects near the robot");
    // Grasp the fruit: at the next publication (1 Hz) it is listed as held, same id as left_held_id.
    let mut c = c0;
    close(&mut sim, &mut c, Side::Left).expect("held");
    let id = sim.io.i32(LEFT_HELD_ID);
    assert_eq!(id, sim.fruit_id(f));
    while sim.io.i64(PLANNING_SCENE_SEQ) < 2 {
        sim.step();
    }
    assert!((sim.t - 1.0).abs() < 1e-9, "published at t = 1 s, not {}", sim.t);
    let scene = PlanningScene::from_cdr(agrisim_fmi::port::latest(&sim.io, PLANNING_SCENE)).unwrap();
    let held = scene.objects.iter().find(|o| o.id == id.to_string()).expect("held fruit listed");
    assert_eq!(held.kind, "fruit_held");
}

#[test]
fn a_second_fruit_lands_on_the_first_in_the_box() {
    let model = RobotModel::load().unwrap();
    let mut placed = vec![];
    let (first, planar, c0) = grasp_setup_nth(Side::Left, 0);
    let mut sim = Sim::start(planar, &c0);
    for (n, f) in [first, grasp_setup_nth(Side::Left, 1).0].into_iter().enumerate() {
        let (_, planar, c0) = grasp_setup_nth(Side::Left, n);
        // Teleport the robot to the fruit (the box and what is in it ride along).
        sim.set(planar, &c0);
        sim.step();
        let mut c = c0;
        close(&mut sim, &mut c, Side::Left).expect("held");
        let over = over_the_box(&model, &c);
        glide(&mut sim, planar, &c, &over, 40, |_, _| {});
        open_left(&mut sim, planar, &over);
        for _ in 0..100 {
            sim.step();
        }
        assert_eq!(sim.io.i32(PLACED_COUNT), n as i32 + 1, "fruit {n} placed");
        placed.push(f);
    }
    let (a, b) = (placed[0], placed[1]);
    let gap = dist(sim.fruit_centre(a), sim.fruit_centre(b)) - 0.5 * (sim.diameter(a) + sim.diameter(b));
    assert!(gap > -0.003, "the second fruit rests on the first, not inside it (gap {gap} m)");
    assert!(gap < 0.05, "released at the same spot: they touch (gap {gap} m)");
    assert_eq!(
        (sim.io.i32(PICKED_COUNT), sim.io.i32(DROPPED_COUNT), sim.io.i32(LAST_PLACED_ID)),
        (2, 0, sim.fruit_id(b))
    );
}

/// Lowers the lift by `step` m per step (the hand pulls the grasped fruit down, away from its
/// truss) until the pedicel breaks or `max` steps; returns the pull outputs seen before.
fn pull_down(sim: &mut Sim, c: &mut Coords, step: f64, max: usize) -> Vec<f64> {
    let planar = sim.planar();
    let mut pulls = vec![];
    for _ in 0..max {
        c.lift -= step;
        sim.set(planar, c);
        sim.step();
        if sim.io.i32(PICKED_COUNT) > 0 {
            break;
        }
        pulls.push(sim.io.f64(LEFT_PEDICEL_PULL));
    }
    pulls
}

#[test]
fn a_grasped_fruit_stays_on_its_plant_until_its_pedicel_breaks() {
    let (f, planar, c0) = grasp_setup(Side::Left);
    let mut sim = Sim::start(planar, &c0);
    let mut c = c0;
    close(&mut sim, &mut c, Side::Left).expect("held");
    assert_eq!((sim.io.i32(LEFT_HELD_ID), sim.io.i32(PICKED_COUNT)), (sim.fruit_id(f), 0), "held, still on the plant");
    let rest = sim.fruit_centre(f);
    let pulls = pull_down(&mut sim, &mut c, 0.002, 200);
    assert_eq!(sim.io.i32(PICKED_COUNT), 1, "the pedicel broke within 40 cm");
    // The load grew as the hand pulled (500 N/m: ~1 N per 2 mm step), and was felt by the hand.
    assert!(pulls.len() > 5, "{pulls:?}");
    assert!(pulls.windows(2).all(|w| w[1] >= w[0] - 1e-9), "{pulls:?}");
    let mode = sim.io.i32(LAST_DETACH_MODE);
    let force = sim.io.f64(LAST_DETACH_FORCE);
    println!(
        "broke in mode {mode} at {force:.2} N after {} steps (last pull {:.2} N)",
        pulls.len() + 1,
        pulls.last().unwrap()
    );
    assert!(mode == 1 || mode == 2, "pull or bend: {mode}");
    assert!(force > 2.0 && force < 60.0, "{force}");
    assert_eq!(sim.io.i32(DETACHED_PULL_COUNT) + sim.io.i32(DETACHED_BEND_COUNT), 1);
    assert!(dist(rest, sim.fruit_centre(f)) > 0.005, "it moved with the hand");
    // Detached: no load on the hand any more, the fruit still in it.
    assert_eq!(sim.io.f64(LEFT_LOAD_FZ), 0.0);
    assert_eq!(sim.io.i32(LEFT_HELD_ID), sim.fruit_id(f));
}

#[test]
fn the_load_on_the_hand_is_the_pedicels_pull() {
    let (_, planar, c0) = grasp_setup(Side::Left);
    let mut sim = Sim::start(planar, &c0);
    let mut c = c0;
    close(&mut sim, &mut c, Side::Left).expect("held");
    pull_down(&mut sim, &mut c, 0.002, 4);
    assert_eq!(sim.io.i32(PICKED_COUNT), 0);
    // The hand pulled down: the pedicel pulls the fruit (and the hand) up, in left_link0 too
    // (its z is base_link's); the force's size is the pedicel's tension and shear.
    let fz = sim.io.f64(LEFT_LOAD_FZ);
    let f = [LEFT_LOAD_FX, LEFT_LOAD_FY, LEFT_LOAD_FZ].map(|v| sim.io.f64(v));
    let size = (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt();
    assert!(fz > 1.0, "{f:?}");
    assert!(sim.io.f64(LEFT_PEDICEL_PULL) <= size + 1e-9 && sim.io.f64(LEFT_PEDICEL_PULL) > 0.5 * size);
    assert_eq!(
        [RIGHT_LOAD_FX, RIGHT_LOAD_FY, RIGHT_LOAD_FZ].map(|v| sim.io.f64(v)),
        [0.0; 3],
        "the right hand holds nothing"
    );
}

#[test]
fn opened_before_the_pedicel_breaks_the_fruit_stays_on_its_plant() {
    let (f, planar, c0) = grasp_setup(Side::Left);
    let mut sim = Sim::start(planar, &c0);
    let rest = sim.fruit_centre(f);
    let mut c = c0;
    close(&mut sim, &mut c, Side::Left).expect("held");
    pull_down(&mut sim, &mut c, 0.002, 3);
    assert_eq!(sim.io.i32(PICKED_COUNT), 0);
    let open = open_left(&mut sim, planar, &c);
    sim.step();
    assert_eq!((sim.io.i32(LEFT_HELD_ID), sim.io.i32(PICKED_COUNT), sim.io.i32(DROPPED_COUNT)), (-1, 0, 0));
    assert!(dist(rest, sim.fruit_centre(f)) < 1e-6, "back where it hung");
    for _ in 0..20 {
        sim.step();
    }
    assert!(dist(rest, sim.fruit_centre(f)) < 1e-6, "and stays there");
    assert_eq!(sim.io.f64(LEFT_LOAD_FZ), 0.0);
    // It can be grasped again: back to the grasp pose, close.
    let mut c = Coords { widths: [0.08, open.widths[1]], ..c0 };
    sim.set(planar, &c);
    sim.step();
    close(&mut sim, &mut c, Side::Left).expect("held again");
}

#[test]
fn squeezing_above_the_bruise_threshold_bruises_the_held_fruit() {
    let (_, planar, c0) = grasp_setup(Side::Left);
    let mut sim = Sim::start(planar, &c0);
    let mut c = c0;
    sim.io.set_f64(LEFT_GRIP_FORCE, 20.0);
    close(&mut sim, &mut c, Side::Left).expect("held");
    sim.step();
    assert_eq!((sim.io.i32(BRUISED_COUNT), sim.io.i32(GRIP_BRUISED_COUNT)), (0, 0), "20 N is below 40 N");
    sim.io.set_f64(LEFT_GRIP_FORCE, 70.0);
    sim.step();
    sim.step();
    assert_eq!((sim.io.i32(BRUISED_COUNT), sim.io.i32(GRIP_BRUISED_COUNT)), (1, 1), "70 N bruises, once");
    sim.io.set_f64(LEFT_GRIP_FORCE, f64::NAN);
    assert!(sim.m.do_step(&mut sim.io, sim.t, H, &mut Quiet).is_err(), "a NaN grip force is an error");
}

/// FMU state serialization with a fruit attached and loaded: saved mid-pull, the rest of the
/// pull (through the break) restores bit for bit.
#[test]
fn serialized_state_restores_with_an_attached_fruit() {
    let (_, planar, c0) = grasp_setup(Side::Left);
    let drive = move |io: &mut Store, k: usize| {
        let mut c = c0;
        // Steps 0-1: open at the fruit; 2-9: closing 1 cm per step; then the lift pulls down 3 mm per step.
        c.widths[0] = (0.08 - 0.01 * k.saturating_sub(1) as f64).max(0.0);
        c.lift -= 0.003 * k.saturating_sub(10) as f64;
        io.set_f64(BASE_X, planar[0]);
        io.set_f64(BASE_Y, planar[1]);
        io.set_f64(BASE_YAW, planar[2]);
        io.set_f64(LIFT_POSITION, c.lift);
        for (i, vr) in q_vrs(Side::Left).into_iter().enumerate() {
            io.set_f64(vr, c.arms[0][i]);
        }
        for (i, vr) in q_vrs(Side::Right).into_iter().enumerate() {
            io.set_f64(vr, c.arms[1][i]);
        }
        io.set_f64(LEFT_FINGER_WIDTH, c.widths[0]);
        io.set_f64(RIGHT_FINGER_WIDTH, c.widths[1]);
        io.set_f64(LEFT_GRIP_FORCE, if k >= 8 { 20.0 } else { 0.0 });
    };
    // Check the drive: attached and loaded at the save point, broken before the end.
    let mut io = Store::new(GreenhouseWorld::VARIABLES);
    *io.value_mut(SCENE_VAR) = Value::String(SCENE.to_string());
    let mut m = GreenhouseWorld::new();
    drive(&mut io, 0);
    m.initialize(&mut io, 0.0, &mut Quiet).unwrap();
    let mut t = 0.0;
    for k in 0..60 {
        drive(&mut io, k);
        m.do_step(&mut io, t, H, &mut Quiet).unwrap();
        t += H;
        if k == 15 {
            assert!(io.i32(LEFT_HELD_ID) >= 0 && io.i32(PICKED_COUNT) == 0 && io.f64(LEFT_PEDICEL_PULL) > 0.0);
        }
    }
    assert_eq!(io.i32(PICKED_COUNT), 1, "the pedicel broke within the run");
    let n = agrisim_fmi_testing::assert_state_round_trip::<GreenhouseWorld>(
        &[(SCENE_VAR, Value::String(SCENE.to_string()))],
        H,
        16,
        44,
        &drive,
    );
    assert!(n > 0);
}
