//! The crop as the camera draws it: fruit that are not one flat colour, breakers with green
//! and coloured parts, calyx pixels labelled as their fruit, leaflets with gaps, and the same
//! bytes for the same inputs.

use agrisim_fmu_camera::crop::{fruit_part, FruitLook, FruitPart};
use agrisim_fmu_camera::lighting::Lighting;
use agrisim_fmu_camera::optics::{CameraPose, Intrinsics, Mount};
use agrisim_fmu_camera::render::{self, DepthModel, DepthNoise, Shot};
use agrisim_fmu_camera::scene::Scene;
use agrisim_math::Rng;
use agrisim_scene::{Kind, Object, Placement, Shape};

/// Camera 0.6 m ahead of base_link, 1.2 m up, looking along +x; fruit 0.35 m ahead of it.
const MOUNT: Mount = Mount { translation: [0.6, 0.0, 1.2], roll: 0.0, pitch: 0.0, yaw: 0.0 };
const X: f64 = 0.95;

fn fruit(id: u32, stage: u8, y: f64, z: f64) -> Object {
    Object {
        id,
        name: format!("fruit{id}"),
        kind: Kind::Fruit { ripeness: stage },
        shape: Shape::Sphere { radius: 0.03 },
        placement: Placement::at(X, y, z),
    }
}

/// A red fruit (id 0) and a breaker (id 1) side by side at eye level, a leaflet (id 2)
/// in front of the gap between them, and a wall behind (id 3).
fn scene() -> Vec<Object> {
    vec![
        fruit(0, 6, 0.045, 1.2),
        fruit(1, 2, -0.045, 1.2),
        Object {
            id: 2,
            name: "leaf0_1".into(),
            kind: Kind::Leaf,
            shape: Shape::Box { half: [0.04, 0.02, 0.001] },
            // Facing the camera (local z -> -x), 0.15 m in front of the fruit, between them.
            placement: Placement::axis_angle([0.8, 0.0, 1.2], [0.0, 1.0, 0.0], -std::f64::consts::FRAC_PI_2),
        },
        Object {
            id: 3,
            name: "wall".into(),
            kind: Kind::Obstacle,
            shape: Shape::Box { half: [0.05, 5.0, 5.0] },
            placement: Placement::at(2.0, 0.0, 1.2),
        },
    ]
}

fn frame(objects: &[Object], light: &Lighting) -> (render::Frame, Intrinsics, CameraPose) {
    let scene = Scene::from_objects(objects);
    let k = Intrinsics::from_fov(320, 240, 40.0, 30.0);
    let pose = CameraPose::new(&MOUNT, 0.0, 0.0, 0.0);
    let depth = DepthModel {
        range: (0.105, 10.0),
        noise: DepthNoise::None,
        baseline: 0.05,
        invalid_band: false,
        edge_ratio: 0.0,
    };
    let f = render::render(
        &Shot { scene: &scene, dynamic: &[], k: &k, pose: &pose, light, columns: &[], depth: &depth },
        &mut Rng::new(1),
        2,
    );
    (f, k, pose)
}

fn pixels(f: &render::Frame, label: i32) -> Vec<[u8; 3]> {
    f.labels
        .iter()
        .enumerate()
        .filter(|(_, &l)| l == label)
        .map(|(i, _)| [f.rgb[3 * i], f.rgb[3 * i + 1], f.rgb[3 * i + 2]])
        .collect()
}

#[test]
fn ripe_fruit_is_not_one_colour_and_a_breaker_is_green_and_red() {
    let (f, ..) = frame(&scene(), &Lighting::new(200.0, 50.0, 0.35));
    let red = pixels(&f, 1);
    assert!(red.len() > 2000, "{} red fruit pixels", red.len());
    let mut distinct: Vec<[u8; 3]> = red.clone();
    distinct.sort();
    distinct.dedup();
    assert!(distinct.len() > 300, "only {} colours on the ripe fruit", distinct.len());
    // Luma spread: shading, highlights and the calyx.
    let luma: Vec<f64> = red.iter().map(|p| 0.299 * p[0] as f64 + 0.587 * p[1] as f64 + 0.114 * p[2] as f64).collect();
    let (lo, hi) = luma.iter().fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    assert!(hi - lo > 80.0, "luma {lo}..{hi}");
    // A highlight: near-white pixels on the red fruit.
    assert!(red.iter().any(|p| p[1] > 150 && p[2] > 130), "no highlight");
    // Mostly red, but with green calyx pixels on top.
    let reddish = red.iter().filter(|p| p[0] as f64 > 1.8 * p[1] as f64).count();
    let greenish = red.iter().filter(|p| p[1] > p[0]).count();
    assert!(reddish > red.len() / 2 && greenish > 20, "{reddish} red, {greenish} green of {}", red.len());
    // The breaker: green over most of it, red-orange at the blossom end (seen from the side,
    // its lowest rows).
    let breaker = pixels(&f, 2);
    let green = breaker.iter().filter(|p| p[1] as f64 > 1.1 * p[0] as f64).count();
    let coloured = breaker.iter().filter(|p| p[0] as f64 > 1.2 * p[1] as f64).count();
    assert!(green > breaker.len() / 2 && coloured > 10, "{green} green, {coloured} coloured of {}", breaker.len());
}

#[test]
fn calyx_pixels_are_labelled_as_their_fruit_and_leaflets_have_gaps() {
    let objects = scene();
    let (f, k, pose) = frame(&objects, &Lighting::new(200.0, 50.0, 0.35));
    let mut calyx = 0;
    for (i, &l) in f.labels.iter().enumerate() {
        if l != 1 && l != 2 {
            continue;
        }
        let o = &objects[(l - 1) as usize];
        let p = pose.to_map(k.reproject((i % 320) as f64, (i / 320) as f64, f.true_depth[i] as f64));
        let c = o.placement.translation;
        let q = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
        // Every pixel labelled a fruit lies on that fruit, inside its collider.
        assert!((q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt() < 0.03 + 1e-4, "{q:?}");
        if fruit_part(o.id, q, 0.03) == FruitPart::Calyx {
            calyx += 1;
        }
    }
    assert!(calyx > 30, "{calyx} calyx pixels");
    // The leaflet's box is 80 x 40 mm; its outline fills part of it: the pixels inside the
    // box's image that show the wall behind are the cut-out.
    let leaf = f.labels.iter().filter(|&&l| l == 3).count();
    assert!(leaf > 500, "{leaf} leaflet pixels");
    let box_px = {
        // The box's silhouette: without the outline the leaflet would be a full rectangle.
        let scale = k.fx / 0.2; // 0.2 m ahead of the camera
        (0.08 * scale) * (0.04 * scale)
    };
    let fill = leaf as f64 / box_px;
    assert!((0.5..0.85).contains(&fill), "leaflet fills {fill} of its box");
    let _ = FruitLook::of(0, 6);
}

#[test]
fn same_inputs_same_bytes() {
    let objects = scene();
    let light = Lighting::new(200.0, 50.0, 0.35);
    let (a, ..) = frame(&objects, &light);
    let (b, ..) = frame(&objects, &light);
    assert_eq!(a, b);
}
