//! Main stems through the Model trait: the robot's base box driven sideways into a plant row
//! presses a stem; the load the FMU reports is the beam's (checked against the contacts it
//! publishes), a shallow press leaves the stem whole, a deep one breaks it (once), and the
//! state with a broken stem restores bit for bit.

use agrisim_fmi::{Model, Quiet, Store, Value};
use agrisim_fmu_greenhouse::ports::SCENE as SCENE_VAR;
use agrisim_fmu_greenhouse::ports::*;
use agrisim_fmu_greenhouse::GreenhouseWorld;
use agrisim_msgs::agrisim::{CollisionState, PlantDamage};
use agrisim_msgs::Message;
use agrisim_scene::scene::Kind;
use agrisim_scene::Shape;

const H: f64 = 0.02;

/// Short plants (0.6 m) with no leaves, so the base box (0.05-0.65 m above the floor) covers
/// a whole stem.
const SCENE: &str = "rows = 2\nactive_rows = 2\nwidth = 12.0\nlength = 20.0\nrow_length = 8.0\nleaf_density = 0\n\
                     plant_height = 0.6\nfruit_height = [0.3, 0.55]\nfruit_per_truss = 1\ntrusses_per_plant = 1";

/// The FMU's defaults (`stem_modulus`, `stem_strength`).
const E: f64 = 100e6;
const SIGMA: f64 = 7e6;
/// The base box's half width (`base_width` 0.9 m).
const HALF_WIDTH: f64 = 0.45;

/// The stem of row 0 nearest x = 4 m: (x, y, radius, length).
fn a_stem() -> (f64, f64, f64, f64) {
    let cfg = agrisim_scene::config::GreenhouseConfig::from_toml_str(SCENE).unwrap();
    let gh = agrisim_scene::generate(&cfg, cfg.seed);
    gh.objects
        .iter()
        .filter(|o| o.kind == Kind::Stem && o.name.starts_with("row0/"))
        .filter_map(|o| match o.shape {
            Shape::Cylinder { radius, half_height } => {
                Some((o.placement.translation[0], o.placement.translation[1], radius, 2.0 * half_height))
            }
            _ => None,
        })
        .min_by(|a, b| (a.0 - 4.0).abs().total_cmp(&(b.0 - 4.0).abs()))
        .expect("row 0 has stems")
}

/// The base_link pose whose box's +y face lies `push` beyond the stem's near surface (the
/// robot faces +x, coming from the -y side), x beside the stem.
fn pose(stem: (f64, f64, f64, f64), push: f64) -> [f64; 3] {
    [stem.0, stem.1 - stem.2 - HALF_WIDTH + push, 0.0]
}

fn drive(io: &mut Store, [x, y, yaw]: [f64; 3]) {
    io.set_f64(BASE_X, x);
    io.set_f64(BASE_Y, y);
    io.set_f64(BASE_YAW, yaw);
}

fn start(at: [f64; 3]) -> (GreenhouseWorld, Store) {
    let mut io = Store::new(GreenhouseWorld::VARIABLES);
    *io.value_mut(SCENE_VAR) = Value::String(SCENE.to_string());
    // A collision_state every step, so the test sees each step's contacts.
    io.set_f64(COLLISION_RATE, 1.0 / H);
    drive(&mut io, at);
    let mut m = GreenhouseWorld::new();
    m.initialize(&mut io, 0.0, &mut Quiet).unwrap();
    (m, io)
}

/// The beam's load ratio for the stem contacts published now: the largest over them.
fn expected_ratio(io: &Store, stem: (f64, f64, f64, f64)) -> Option<f64> {
    let s = CollisionState::from_cdr(agrisim_fmi::port::latest(io, COLLISION_STATE)).unwrap();
    let (r, l) = (stem.2, stem.3);
    s.contacts
        .iter()
        .filter(|c| c.object_kind == "stem" && (c.position.x - stem.0).abs() < 0.05)
        .map(|c| {
            let a = c.position.z.clamp(r, l - r);
            3.0 * E * r * c.depth / (SIGMA * a * (l - a))
        })
        .reduce(f64::max)
}

#[test]
fn a_stem_pressed_beyond_its_strength_breaks_once() {
    let stem = a_stem();
    let (mut m, mut io) = start(pose(stem, -0.05));
    let mut t = 0.0;
    let mut step = |m: &mut GreenhouseWorld, io: &mut Store, push: f64| {
        drive(io, pose(stem, push));
        m.do_step(io, t, H, &mut Quiet).unwrap();
        t += H;
    };
    assert_eq!((io.i32(STEMS_BROKEN_COUNT), io.f64(PEAK_STEM_LOAD)), (0, 0.0));
    // A shallow press, 1 mm at a time to 6 mm: the load grows, the stem holds.
    let mut peak: f64 = 0.0;
    for k in 1..=6 {
        step(&mut m, &mut io, 0.001 * k as f64);
        let now = expected_ratio(&io, stem).expect("the box presses the stem");
        peak = peak.max(now);
        let got = io.f64(PEAK_STEM_LOAD);
        assert!((got - peak).abs() <= 1e-4 * peak, "step {k}: FMU {got}, beam {peak}");
    }
    assert!(peak > 0.0 && peak < 1.0, "a 6 mm press holds: {peak}");
    assert_eq!(io.i32(STEMS_BROKEN_COUNT), 0);
    assert!(io.f64(PEAK_STEM_FORCE) > 0.0);
    // Deeper, 5 mm a step, until it breaks: at the first step the beam's load reaches its
    // strength, not before.
    let mut broke_at = None;
    for k in 1..=60 {
        let push = 0.006 + 0.005 * k as f64;
        step(&mut m, &mut io, push);
        let now = expected_ratio(&io, stem).expect("the box presses the stem");
        if io.i32(STEMS_BROKEN_COUNT) > 0 {
            assert!(now >= 1.0, "broken at a load of {now}");
            broke_at = Some(push);
            break;
        }
        assert!(now < 1.0, "{now} at {push} m, not broken");
    }
    let push = broke_at.expect("a deep enough press breaks the stem");
    // The contact height is parry's choice along the overlap; the beam then needs
    // sigma a b / (3 E r): 0.175 m at most for this 0.6 m stem, at mid-height.
    assert!(push < 0.2, "{push}");
    let damage = PlantDamage::from_cdr(agrisim_fmi::port::latest(&io, PLANT_DAMAGE)).unwrap();
    assert_eq!(damage.stems_broken, 1);
    assert!(io.f64(PEAK_STEM_LOAD) >= 1.0);
    // Pressed further and backed off: still one broken stem.
    step(&mut m, &mut io, push + 0.01);
    step(&mut m, &mut io, -0.05);
    assert_eq!(io.i32(STEMS_BROKEN_COUNT), 1);
}

#[test]
fn a_weaker_stem_breaks_under_a_shallower_press() {
    // The strength is a parameter: at a hundredth of the default, a press that the default
    // stem holds breaks it.
    let stem = a_stem();
    let mut io = Store::new(GreenhouseWorld::VARIABLES);
    *io.value_mut(SCENE_VAR) = Value::String(SCENE.to_string());
    io.set_f64(STEM_STRENGTH, SIGMA / 100.0);
    drive(&mut io, pose(stem, 0.006));
    let mut m = GreenhouseWorld::new();
    m.initialize(&mut io, 0.0, &mut Quiet).unwrap();
    m.do_step(&mut io, 0.0, H, &mut Quiet).unwrap();
    assert_eq!(io.i32(STEMS_BROKEN_COUNT), 1);
    // A strength of zero is refused, naming the parameter.
    let mut io = Store::new(GreenhouseWorld::VARIABLES);
    *io.value_mut(SCENE_VAR) = Value::String(SCENE.to_string());
    io.set_f64(STEM_STRENGTH, 0.0);
    let e = GreenhouseWorld::new().initialize(&mut io, 0.0, &mut Quiet).err().unwrap();
    assert!(e.contains("stem_strength"), "{e}");
}

/// Saved mid-press, the rest of the press (through the break) restores bit for bit.
#[test]
fn serialized_state_restores_through_a_stem_break() {
    let stem = a_stem();
    let drive = move |io: &mut Store, k: usize| drive(io, pose(stem, -0.02 + 0.005 * k as f64));
    let n = agrisim_fmi_testing::assert_state_round_trip::<GreenhouseWorld>(
        &[(SCENE_VAR, Value::String(SCENE.to_string()))],
        H,
        8,
        40,
        &drive,
    );
    assert!(n > 0);
    // The drive breaks the stem after the save point.
    let (mut m, mut io) = start(pose(stem, -0.02));
    for k in 0..48 {
        drive(&mut io, k);
        m.do_step(&mut io, k as f64 * H, H, &mut Quiet).unwrap();
        if k == 8 {
            assert_eq!(io.i32(STEMS_BROKEN_COUNT), 0);
        }
    }
    assert_eq!(io.i32(STEMS_BROKEN_COUNT), 1);
}
