//! The Greenhouse model against analytic answers and its own contracts, through the Model trait.

use agrisim_fmi::{Model, Quiet, Store, Value};
use agrisim_fmu_greenhouse::ports::*;
use agrisim_fmu_greenhouse::GreenhouseWorld;
use agrisim_msgs::agrisim::CollisionState;
use agrisim_msgs::geometry_msgs::{PoseArray, PoseStamped};
use agrisim_msgs::Message;
use agrisim_scene::config::GreenhouseConfig;
use agrisim_scene::layout::Layout;
use agrisim_scene::Shape;

const H: f64 = 0.02;

/// A Greenhouse with `scene` as its TOML, the base at `pose`, initialized at t = 0.
fn start(scene: &str, pose: [f64; 3], setup: impl FnOnce(&mut Store)) -> (GreenhouseWorld, Store) {
    let mut io = Store::new(GreenhouseWorld::VARIABLES);
    *io.value_mut(SCENE) = Value::String(scene.to_string());
    set_pose(&mut io, pose);
    setup(&mut io);
    let mut m = GreenhouseWorld::new();
    m.initialize(&mut io, 0.0, &mut Quiet).unwrap();
    (m, io)
}

fn set_pose(io: &mut Store, [x, y, yaw]: [f64; 3]) {
    io.set_f64(BASE_X, x);
    io.set_f64(BASE_Y, y);
    io.set_f64(BASE_YAW, yaw);
}

fn layout(scene: &str) -> Layout {
    Layout::from_config(&GreenhouseConfig::from_toml_str(scene).unwrap())
}

fn collision_state(io: &Store) -> CollisionState {
    CollisionState::from_cdr(agrisim_fmi::port::latest(io, COLLISION_STATE)).unwrap()
}

/// Steps the base from `from` toward `to` in `n` equal moves (one per step) until it collides;
/// returns the step index of the first collision.
fn drive_until_contact(
    m: &mut GreenhouseWorld,
    io: &mut Store,
    from: [f64; 3],
    to: [f64; 3],
    n: usize,
) -> Option<usize> {
    for k in 1..=n {
        let f = k as f64 / n as f64;
        set_pose(io, std::array::from_fn(|i| from[i] + f * (to[i] - from[i])));
        m.do_step(io, (k - 1) as f64 * H, H, &mut Quiet).unwrap();
        if io.bool(COLLISION) {
            return Some(k);
        }
    }
    None
}

#[test]
fn start_pose_and_aisles_are_collision_free() {
    let l = layout("");
    let (mut m, mut io) = start("", l.start_pose, |_| {});
    assert!(!io.bool(COLLISION));
    assert_eq!(io.i32(COLLISION_COUNT), 0);
    assert!(io.f64(MIN_CLEARANCE) > 0.3, "clearance at the start {}", io.f64(MIN_CLEARANCE));
    let s = collision_state(&io);
    assert!(!s.in_collision && s.contacts.is_empty() && s.header.frame_id == "map");
    // Along every aisle's centre line, end to end: nothing touched, clearance about
    // (aisle width - base width) / 2 = 0.55 m to the row envelopes.
    for a in &l.aisles {
        let hit = drive_until_contact(&mut m, &mut io, [a.x_start, a.y, 0.0], [a.x_end, a.y, 0.0], 150);
        assert_eq!(hit, None, "collision in aisle {}: {:?}", a.index, collision_state(&io));
        let c = io.f64(MIN_CLEARANCE);
        assert!(c > 0.3 && c < 0.8, "clearance in aisle {}: {c}", a.index);
    }
}

/// Rows of bare stems, no pipes: a row's first post is the first thing on the row line.
const POST_SCENE: &str = "heating_pipes = false\nleaf_density = 0\ntrusses_per_plant = 0";

#[test]
fn driving_into_the_first_post_of_a_row_reports_it() {
    let cfg = GreenhouseConfig::from_toml_str(POST_SCENE).unwrap();
    let gh = agrisim_scene::generate(&cfg, cfg.seed);
    let row = &gh.layout.rows[2];
    let post = gh.objects.iter().find(|o| o.name == "row2/post0").expect("row 2 has posts");
    let Shape::Cylinder { radius, .. } = post.shape else { panic!("posts are cylinders") };
    let face = post.placement.translation[0] - radius;
    // Along the row line from the headland, 1 mm per step.
    let half_len = 0.6;
    let from = [face - half_len - 0.5, row.y, 0.0];
    let to = [face - half_len + 0.02, row.y, 0.0];
    let (mut m, mut io) = start(POST_SCENE, from, |_| {});
    assert!(!io.bool(COLLISION));
    let k = drive_until_contact(&mut m, &mut io, from, to, 520).expect("the post is hit");
    let front = io.f64(BASE_X) + half_len;
    let s = collision_state(&io);
    assert!(
        (front - face).abs() < 0.002,
        "first contact with the front at {front}, post face at {face} (step {k}): {s:?}"
    );
    assert!(s.in_collision);
    assert_eq!(s.count, 1, "{s:?}");
    let c = &s.contacts[0];
    assert_eq!(
        (c.object_name.as_str(), c.object_kind.as_str(), c.robot_link.as_str()),
        ("row2/post0", "post", "base_link")
    );
    assert_eq!(c.object_id, post.id);
    // Normal from the object to the robot: -x; contact on the post's front face.
    assert!(c.normal.x < -0.999, "normal {:?}", c.normal);
    assert!((c.position.x - face).abs() < 0.002 && (c.position.y - row.y).abs() < 0.01, "{:?}", c.position);
    assert!(c.depth >= 0.0 && c.depth < 0.002);
    assert_eq!(io.i32(COLLISION_COUNT), 1);
    assert_eq!(io.f64(MIN_CLEARANCE), 0.0);
}

#[test]
fn driving_sideways_into_a_plant_row_hits_the_plants() {
    let l = layout("");
    let aisle = &l.aisles[1];
    let x = 0.5 * (aisle.x_start + aisle.x_end) + 0.13;
    let from = [x, aisle.y, 0.0];
    let to = [x, aisle.y - 1.2, 0.0]; // toward the row below the aisle
    let (mut m, mut io) = start("", from, |_| {});
    drive_until_contact(&mut m, &mut io, from, to, 240).expect("the row is hit");
    let s = collision_state(&io);
    assert!(s.in_collision && !s.contacts.is_empty());
    for c in &s.contacts {
        assert!(["leaf", "fruit", "truss", "stem", "post"].contains(&c.object_kind.as_str()), "{c:?}");
        assert!(c.object_name.starts_with(&format!("row{}/", aisle.index)), "{c:?}");
        // The robot came from +y: the object pushes it back toward +y.
        assert!(c.normal.y > 0.3, "normal {:?} of {}", c.normal, c.object_name);
        let n = (c.normal.x.powi(2) + c.normal.y.powi(2) + c.normal.z.powi(2)).sqrt();
        assert!((n - 1.0).abs() < 1e-3);
    }
    // The box's side at y - 0.45 reached the row envelope (row_width 0.6 -> 0.3 m from the row line).
    let side = io.f64(BASE_Y) - 0.45;
    let row_y = l.rows[aisle.index].y;
    assert!(side - row_y <= 0.3 + 0.011 && side - row_y > 0.0, "side {side} vs row line {row_y}");
}

/// A hall with two rows, a 4 m aisle between them (centre y = 5, row envelopes from y = 3
/// to 7) and a placed box obstacle in it, nothing else near.
const OBSTACLE_SCENE: &str = r#"
rows = 2
active_rows = 2
aisle_width = 4.0
width = 10.0
length = 30.0
row_length = 20.0
[[obstacles]]
x = 15.0
y = 5.0
size_x = 0.4
size_y = 0.5
height = 1.0
"#;

#[test]
fn min_clearance_matches_the_distance_to_a_placed_obstacle() {
    let l = layout(OBSTACLE_SCENE);
    assert_eq!(l.aisles.len(), 1);
    assert!((l.aisles[0].y - 5.0).abs() < 1e-9);
    // Facing the obstacle: gap between the box front (x + 0.6) and the obstacle face (14.8).
    for gap in [0.05, 0.2, 0.37, 0.5] {
        let (_, io) = start(OBSTACLE_SCENE, [14.8 - 0.6 - gap, 5.0, 0.0], |_| {});
        assert!((io.f64(MIN_CLEARANCE) - gap).abs() < 0.01, "gap {gap}: min_clearance {}", io.f64(MIN_CLEARANCE));
    }
    // Turned by 90 deg: the box's side (half width 0.45) faces the obstacle.
    let (_, io) = start(OBSTACLE_SCENE, [14.8 - 0.45 - 0.3, 5.0, std::f64::consts::FRAC_PI_2], |_| {});
    assert!((io.f64(MIN_CLEARANCE) - 0.3).abs() < 0.01, "{}", io.f64(MIN_CLEARANCE));
    // Diagonally off the obstacle's corner (14.8, 5.25): corner-to-corner distance.
    let (dx, dy) = (0.3, 0.2);
    let (_, io) = start(OBSTACLE_SCENE, [14.8 - 0.6 - dx, 5.25 + 0.45 + dy, 0.0], |_| {});
    let analytic = (dx * dx + dy * dy).sqrt();
    assert!((io.f64(MIN_CLEARANCE) - analytic).abs() < 0.01, "{} vs {analytic}", io.f64(MIN_CLEARANCE));
    // In the headland, 0.9 m from the front wall's inner face (x = 0); beyond the cap: the cap.
    let (_, io) = start(OBSTACLE_SCENE, [1.5, 5.0, 0.0], |_| {});
    assert!((io.f64(MIN_CLEARANCE) - 0.9).abs() < 0.01, "{}", io.f64(MIN_CLEARANCE));
    let (_, io) = start(OBSTACLE_SCENE, [1.5, 5.0, 0.0], |io| io.set_f64(CLEARANCE_CAP, 0.5));
    assert_eq!(io.f64(MIN_CLEARANCE), 0.5);
}

#[test]
fn contact_onsets_are_counted_once_per_touch() {
    let (mut m, mut io) = start(OBSTACLE_SCENE, [14.0, 5.0, 0.0], |_| {});
    let (out, touch) = ([14.0, 5.0, 0.0], [14.8 - 0.6 + 0.01, 5.0, 0.0]);
    let mut seqs = vec![];
    for (k, (pose, contacts)) in [(touch, 1), (touch, 1), (out, 0), (touch, 1), (out, 0)].into_iter().enumerate() {
        set_pose(&mut io, pose);
        m.do_step(&mut io, k as f64 * 0.013, 0.013, &mut Quiet).unwrap();
        let s = collision_state(&io);
        assert_eq!(s.contacts.len(), contacts);
        seqs.push(io.i64(COLLISION_STATE_SEQ));
        if contacts == 1 {
            assert_eq!(s.contacts[0].object_name, "obstacle0");
            assert_eq!(s.contacts[0].object_kind, "obstacle");
            assert!((s.contacts[0].depth - 0.01).abs() < 1e-3, "{}", s.contacts[0].depth);
        }
    }
    assert_eq!(io.i32(COLLISION_COUNT), 2);
    // Every change of the contact set publishes at once (steps of 13 ms, 10 Hz schedule):
    // steps 1, 3, 4, 5 change the set; step 2 (t = 26 ms) neither changes nor is due.
    assert_eq!(seqs, vec![2, 2, 3, 4, 5]);
}

#[test]
fn ground_truth_fruit_and_target() {
    let l = layout("");
    let (mut m, mut io) = start("", l.start_pose, |io| io.set_i32(TARGET_FRUIT, 17));
    let n = io.i32(FRUIT_COUNT) as usize;
    assert_eq!(n, 6 * 60 * 4 * 5, "6 rows x 60 plants x 4 trusses x 5 fruit");
    let poses = PoseArray::from_cdr(agrisim_fmi::port::latest(&io, FRUIT_POSES)).unwrap();
    assert_eq!((poses.poses.len(), poses.header.frame_id.as_str()), (n, "map"));
    assert_eq!(io.i64(FRUIT_POSES_SEQ), 1);
    let target = PoseStamped::from_cdr(agrisim_fmi::port::latest(&io, TARGET)).unwrap();
    let p17 = poses.poses[17].position;
    assert_eq!(target.pose.position, p17);
    assert!(io.bool(TARGET_VALID) && io.i32(TARGET_ID) >= 0);
    assert_eq!([io.f64(TARGET_X), io.f64(TARGET_Y), io.f64(TARGET_Z)], [p17.x, p17.y, p17.z]);
    assert!(p17.z >= 0.5 && p17.z <= 1.8, "fruit height band");
    // fruit_rate 1 Hz: 1 s of 0.02 s steps publishes once more (at t = 1 s); the target too.
    for k in 0..50 {
        m.do_step(&mut io, k as f64 * H, H, &mut Quiet).unwrap();
    }
    assert_eq!((io.i64(FRUIT_POSES_SEQ), io.i64(TARGET_SEQ)), (2, 2));
    assert_eq!(
        PoseArray::from_cdr(agrisim_fmi::port::latest(&io, FRUIT_POSES)).unwrap().header.stamp.to_nanos(),
        1_000_000_000
    );
    // Selecting another fruit publishes it at once; -1 clears the scalars.
    io.set_i32(TARGET_FRUIT, 3);
    m.do_step(&mut io, 1.0, H, &mut Quiet).unwrap();
    assert_eq!(io.i64(TARGET_SEQ), 3);
    assert_eq!(
        PoseStamped::from_cdr(agrisim_fmi::port::latest(&io, TARGET)).unwrap().pose.position,
        poses.poses[3].position
    );
    io.set_i32(TARGET_FRUIT, -1);
    m.do_step(&mut io, 1.02, H, &mut Quiet).unwrap();
    assert!(!io.bool(TARGET_VALID));
    assert_eq!((io.i32(TARGET_ID), io.f64(TARGET_X)), (-1, 0.0));
    assert_eq!(io.i64(TARGET_SEQ), 3);
    io.set_i32(TARGET_FRUIT, n as i32);
    m.do_step(&mut io, 1.04, H, &mut Quiet).unwrap();
    assert!(!io.bool(TARGET_VALID), "index past the fruit list");
}

#[test]
fn same_inputs_same_outputs_and_the_seed_matters() {
    let l = layout("");
    let a = &l.aisles[0];
    let run = |seed: i32| {
        let (mut m, mut io) = start("", l.start_pose, |io| {
            io.set_i32(SEED, seed);
            io.set_i32(TARGET_FRUIT, 5);
        });
        let mut trace = vec![io.clone()];
        for k in 0..100 {
            let f = k as f64 / 100.0;
            // Into the aisle and then into the row on its right.
            set_pose(&mut io, [l.start_pose[0] + f * (a.x_start + 3.0 - l.start_pose[0]), a.y - f * f * 0.9, -0.3 * f]);
            m.do_step(&mut io, k as f64 * H, H, &mut Quiet).unwrap();
            trace.push(io.clone());
        }
        trace
    };
    let (one, two) = (run(7), run(7));
    assert!(one == two, "same seed and inputs must give identical outputs");
    assert!(one.last().unwrap().i32(COLLISION_COUNT) > 0, "the run should touch the row");
    let other = run(8);
    assert_ne!(one[0].binary(FRUIT_POSES), other[0].binary(FRUIT_POSES));
}

#[test]
fn bad_parameters_and_inputs_are_errors() {
    let init = |setup: &dyn Fn(&mut Store)| {
        let mut io = Store::new(GreenhouseWorld::VARIABLES);
        setup(&mut io);
        GreenhouseWorld::new().initialize(&mut io, 0.0, &mut Quiet)
    };
    let e = init(&|io| *io.value_mut(SCENE) = Value::String("rows = 0".into())).unwrap_err();
    assert!(e.contains("rows"), "{e}");
    let e = init(&|io| *io.value_mut(SCENE) = Value::String("rowz = 3".into())).unwrap_err();
    assert!(e.contains("rowz"), "{e}");
    assert!(init(&|io| io.set_f64(BASE_WIDTH, 0.0)).is_err());
    assert!(init(&|io| io.set_f64(COLLISION_RATE, -1.0)).is_err());
    assert!(init(&|io| io.set_f64(BASE_X, f64::NAN)).is_err());
    let (mut m, mut io) = start("", layout("").start_pose, |_| {});
    io.set_f64(BASE_YAW, f64::INFINITY);
    assert!(m.do_step(&mut io, 0.0, H, &mut Quiet).is_err());
}

#[test]
fn the_160_row_house_loads_and_runs() {
    // The paper's complete layout: 160 rows at a 2.6 m pitch need a 416 m wide hall.
    let scene = "rows = 160\nwidth = 420.0";
    let l = layout(scene);
    let (mut m, mut io) = start(scene, l.start_pose, |io| io.set_i32(TARGET_FRUIT, 191_999));
    assert_eq!(io.i32(FRUIT_COUNT), 160 * 60 * 20);
    assert!(io.bool(TARGET_VALID) && !io.bool(COLLISION));
    let a = &l.aisles[4];
    let hit = drive_until_contact(&mut m, &mut io, [a.x_start, a.y, 0.0], [a.x_end, a.y, 0.0], 60);
    assert_eq!(hit, None);
}
