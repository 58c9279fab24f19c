//! The occupancy map against analytic scenes (a plane in front of the camera), a brute-force
//! reference on random scans, and the node on the bus.

use agrisim_bus::{Bus, Node};
use agrisim_mapping::node::{CAMERA_INFO, DEPTH, SCENE, STATUS, TF};
use agrisim_mapping::{
    DepthFrame, DepthMapper, Grid, Intrinsics, Key, MapConfig, MapperConfig, Occupancy, OccupancyMap, Primitive, Shape,
    Sphere, OCCUPIED_KIND,
};
use agrisim_msgs::agrisim::{FmuStatus, PlanningScene};
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::sensor_msgs::{CameraInfo, Image};
use agrisim_msgs::shape_msgs::SolidPrimitive;
use agrisim_msgs::std_msgs::Header;
use agrisim_msgs::Message;
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3 as V3};
use proptest::prelude::*;
use std::collections::{BTreeMap, BTreeSet};

mod common;
use common::tf;

const W: usize = 64;
const H: usize = 48;

fn k() -> Intrinsics {
    Intrinsics { fx: 50.0, fy: 50.0, cx: 32.0, cy: 24.0 }
}

/// A camera at the origin looking along +z of the map (optical frame = map frame), seeing a
/// wall at depth `z` everywhere.
fn wall(z: f32) -> DepthFrame {
    DepthFrame { width: W, height: H, z: vec![z; W * H] }
}

fn map(config: MapConfig) -> OccupancyMap {
    OccupancyMap::new(config).unwrap()
}

fn p(x: f64, y: f64, z: f64) -> Point3<f64> {
    Point3::new(x, y, z)
}

#[test]
fn a_wall_is_occupied_at_its_depth_and_free_in_front() {
    let mut m = map(MapConfig::default());
    let s = m.insert_depth(&wall(1.005), &k(), &Isometry3::identity(), &[]);
    assert_eq!(s.points, W * H);
    assert_eq!((s.self_filtered, s.clipped, s.dropped), (0, 0, 0));
    let occ = m.occupied();
    assert!(occ.len() > 1000, "{}", occ.len());
    // Depth 1.005 m is inside voxel layer 100 (1.00..1.01 m): only that layer.
    assert!(occ.iter().all(|k| k[2] == 100), "{:?}", occ.iter().find(|k| k[2] != 100));
    // The wall spans x in +-32/50 m at 1 m: its voxels reach about 0.64 m either side.
    let xs: BTreeSet<i32> = occ.iter().map(|k| k[0]).collect();
    let (lo, hi) = (*xs.first().unwrap(), *xs.last().unwrap());
    assert!((-64..=-63).contains(&lo) && (62..=63).contains(&hi), "{lo} {hi}");
    for z in [0.005, 0.3, 0.7, 0.995] {
        assert_eq!(m.state_at(&p(0.001, 0.001, z)), Occupancy::Free, "z = {z}");
    }
    assert_eq!(m.state_at(&p(0.015, 0.015, 1.005)), Occupancy::Occupied);
    // The pixel at (32, 24) ends at x = y = 0.01005 m (voxel 1, 1).
    // Behind the wall and outside the field of view: never seen.
    assert_eq!(m.state_at(&p(0.001, 0.001, 1.05)), Occupancy::Unknown);
    assert_eq!(m.state_at(&p(0.9, 0.0, 0.5)), Occupancy::Unknown);
    // OctoMap's sensor model: one hit is logodds(0.7), one miss logodds(0.4).
    let hit = (0.7f64 / 0.3).ln() as f32;
    let miss = (0.4f64 / 0.6).ln() as f32;
    assert_eq!(m.log_odds(&[1, 1, 100]), Some(hit));
    assert_eq!(m.log_odds(&[0, 0, 50]), Some(miss));
}

#[test]
fn beyond_max_range_clears_but_does_not_occupy() {
    let mut m = map(MapConfig { max_range: 0.5, ..MapConfig::default() });
    let s = m.insert_depth(&wall(1.005), &k(), &Isometry3::identity(), &[]);
    assert_eq!(s.clipped, W * H);
    assert!(m.occupied().is_empty());
    assert_eq!(m.state_at(&p(0.001, 0.001, 0.45)), Occupancy::Free);
    assert_eq!(m.state_at(&p(0.001, 0.001, 0.6)), Occupancy::Unknown);
}

#[test]
fn ray_clearing_removes_a_stale_obstacle() {
    let mut m = map(MapConfig::default());
    m.insert_depth(&wall(0.505), &k(), &Isometry3::identity(), &[]);
    assert_eq!(m.state_at(&p(0.001, 0.001, 0.505)), Occupancy::Occupied);
    assert!(m.collides_sphere(&p(0.0, 0.0, 0.45), 0.05));
    // The obstacle is gone: the wall behind it is seen through its place. One hit
    // (+0.85) outweighs two misses (-0.41 each), not three.
    for n in 1..=3 {
        m.insert_depth(&wall(1.005), &k(), &Isometry3::identity(), &[]);
        let expect = if n < 3 { Occupancy::Occupied } else { Occupancy::Free };
        assert_eq!(m.state_at(&p(0.001, 0.001, 0.505)), expect, "after {n} clearing scans");
    }
    assert!(m.occupied().iter().all(|k| k[2] == 100));
    assert!(!m.collides_sphere(&p(0.0, 0.0, 0.45), 0.05));
    assert!(m.collides_sphere(&p(0.0, 0.0, 0.95), 0.05));
}

#[test]
fn the_robot_is_filtered_out_and_its_rays_still_clear() {
    // A link (a box 10 cm wide) in front of part of the wall, as if the arm's forearm sat
    // there: the wall points inside it (grown by the self padding) are the robot.
    let link = Primitive::new(Shape::Box { size: [0.1, 0.1, 0.1] }, Isometry3::translation(0.2, 0.0, 1.0));
    let config = MapConfig { self_padding: 0.0, ..MapConfig::default() };
    let mut m = map(config.clone());
    let s = m.insert_depth(&wall(1.005), &k(), &Isometry3::identity(), &[link]);
    assert!(s.self_filtered > 0 && s.self_filtered < W * H, "{s:?}");
    let mut plain = map(config);
    plain.insert_depth(&wall(1.005), &k(), &Isometry3::identity(), &[]);
    let (a, b): (BTreeSet<Key>, BTreeSet<Key>) =
        (m.occupied().into_iter().collect(), plain.occupied().into_iter().collect());
    let gone: Vec<&Key> = b.difference(&a).collect();
    assert!(!gone.is_empty() && a.is_subset(&b));
    let g = *m.grid();
    for k in &gone {
        // Every dropped voxel holds a point on the link, and is free, not unknown.
        let c = p(g.center(k[0]), g.center(k[1]), g.center(k[2]));
        assert!(link.distance(&c) <= 0.5 * 0.01 * 3f64.sqrt(), "{k:?}");
        assert_eq!(m.state(k), Occupancy::Free);
    }
    assert!(!m.collides_point(&p(0.2, 0.0, 1.005)));
    assert!(m.collides_point(&p(-0.2, 0.0, 1.005)));
}

#[test]
fn the_allowed_fruit_is_left_out_of_queries_and_exports() {
    let mut m = map(MapConfig::default());
    m.insert_depth(&wall(1.005), &k(), &Isometry3::identity(), &[]);
    let fruit = Sphere { center: p(0.0, 0.0, 1.03), radius: 0.03 };
    assert!(m.collides_sphere(&p(0.0, 0.0, 0.99), 0.01));
    let before = m.occupied().len();
    m.set_allowed(vec![fruit]);
    assert!(!m.collides_sphere(&p(0.0, 0.0, 0.99), 0.01));
    assert!(m.collides_sphere(&p(0.2, 0.0, 0.99), 0.01));
    let after = m.occupied();
    assert!(after.len() < before);
    // Nothing exported touches the fruit; the map still knows those voxels.
    let g = *m.grid();
    for k in &after {
        let (lo, hi) = g.bounds(k);
        let c = fruit.center;
        let d2: f64 = (0..3).map(|i| (lo[i] - c[i]).max(c[i] - hi[i]).max(0.0).powi(2)).sum();
        assert!(d2 > fruit.radius * fruit.radius, "{k:?}");
    }
    assert_eq!(m.state_at(&p(0.015, 0.015, 1.005)), Occupancy::Occupied);
    m.set_allowed(Vec::new());
    assert_eq!(m.occupied().len(), before);
}

#[test]
fn padding_grows_the_obstacles() {
    // The wall's near face is at z = 1.00 m.
    let at = |padding: f64| {
        let mut m = map(MapConfig { padding, ..MapConfig::default() });
        m.insert_depth(&wall(1.005), &k(), &Isometry3::identity(), &[]);
        m
    };
    let (bare, padded) = (at(0.0), at(0.03));
    // A point 5 mm in front of the face.
    assert!(!bare.collides_point(&p(0.0, 0.0, 0.995)));
    assert!(padded.collides_point(&p(0.0, 0.0, 0.995)));
    // A sphere of 4 cm at 5 cm from the face: clear of the wall, but not of the padding.
    assert!(!bare.collides_sphere(&p(0.0, 0.0, 0.95), 0.04));
    assert!(padded.collides_sphere(&p(0.0, 0.0, 0.95), 0.04));
    assert!(!padded.collides_sphere(&p(0.0, 0.0, 0.9), 0.04));
    // A capsule across the view, 3 cm in front of the face.
    let (a, b) = (p(-0.3, 0.0, 0.97), p(0.3, 0.0, 0.97));
    assert!(!bare.collides_capsule(&a, &b, 0.025));
    assert!(bare.collides_capsule(&a, &b, 0.035));
    assert!(padded.collides_capsule(&a, &b, 0.005));
    assert!(!padded.collides_capsule(&p(-0.3, 0.0, 0.9), &p(0.3, 0.0, 0.9), 0.05));
    // Queries outside the map or with nonsense are no collision, never a panic.
    assert!(!bare.collides_sphere(&p(f64::NAN, 0.0, 0.0), 0.1));
    assert!(!bare.collides_sphere(&p(1e9, 0.0, 0.0), 0.1));
}

#[test]
fn the_planning_scene_is_the_occupied_voxels_in_boxes() {
    // 2 cm voxels: the pixels at 1 m are 2 cm apart, so the wall is solid.
    let mut m = map(MapConfig { resolution: 0.02, ..MapConfig::default() });
    // A wall with a step: the left half at 1.0 m, the right at 1.2 m.
    let mut d = wall(1.005);
    for v in 0..H {
        for u in W / 2..W {
            d.z[v * W + u] = 1.205;
        }
    }
    m.insert_depth(&d, &k(), &Isometry3::identity(), &[]);
    let header = Header { stamp: Time::from_nanos(5), frame_id: "map".into() };
    let scene = m.planning_scene(header.clone(), 0.0);
    assert_eq!(scene.header, header);
    let occ: BTreeSet<Key> = m.occupied().into_iter().collect();
    assert!(scene.objects.len() * 10 < occ.len(), "{} boxes for {} voxels", scene.objects.len(), occ.len());
    let mut covered = BTreeSet::new();
    for o in &scene.objects {
        assert_eq!(o.kind, OCCUPIED_KIND);
        assert_eq!(o.primitive.r#type, SolidPrimitive::BOX);
        let prim = Primitive::from_msg(&o.primitive, &o.pose).unwrap();
        let Shape::Box { size } = prim.shape else { panic!() };
        let c = o.pose.position;
        let lo = [c.x - size[0] / 2.0, c.y - size[1] / 2.0, c.z - size[2] / 2.0];
        let n = [0, 1, 2].map(|i| (size[i] / 0.02).round() as i32);
        let k0 = [0, 1, 2].map(|i| (lo[i] / 0.02).round() as i32);
        for x in 0..n[0] {
            for y in 0..n[1] {
                for z in 0..n[2] {
                    assert!(covered.insert([k0[0] + x, k0[1] + y, k0[2] + z]), "boxes overlap");
                }
            }
        }
    }
    assert_eq!(covered, occ);
    let grown = m.planning_scene(Header::default(), 0.02);
    assert!((grown.objects[0].primitive.dimensions[0] - scene.objects[0].primitive.dimensions[0] - 0.04).abs() < 1e-12);
    // It goes through the message layer unchanged.
    assert_eq!(PlanningScene::from_cdr(&scene.to_cdr()).unwrap(), scene);
}

/// The map's contract, computed the slow way: after one scan from an empty map, a voxel is
/// occupied when a point within range (not on the robot) ends in it, free when some ray walks
/// it (or a robot point ends in it) and it is no such end, otherwise unknown.
fn reference(
    config: &MapConfig,
    origin: &[f32; 3],
    points: &[[f32; 3]],
    robot: &[Primitive],
) -> BTreeMap<Key, Occupancy> {
    let g = Grid::new(config.resolution);
    let (mut hit, mut model, mut free) = (BTreeSet::new(), BTreeSet::new(), BTreeSet::new());
    for q in points {
        let d = ((q[0] - origin[0]).powi(2) + (q[1] - origin[1]).powi(2) + (q[2] - origin[2]).powi(2)) as f64;
        let end = if d.sqrt() <= config.max_range {
            let on = robot.iter().any(|l| l.contains(&p(q[0] as f64, q[1] as f64, q[2] as f64), config.self_padding));
            if let Some(k) = g.key(q) {
                if on {
                    model.insert(k);
                } else {
                    hit.insert(k);
                }
            }
            *q
        } else {
            agrisim_mapping::ray::clip(origin, q, config.max_range as f32)
        };
        g.walk(origin, &end, |k| {
            free.insert(k);
        });
    }
    let mut out = BTreeMap::new();
    for k in free.iter().chain(&model) {
        out.insert(*k, Occupancy::Free);
    }
    for k in hit.difference(&model) {
        out.insert(*k, Occupancy::Occupied);
    }
    out
}

fn scan_strategy() -> impl Strategy<Value = ([f32; 3], Vec<[f32; 3]>)> {
    (
        prop::array::uniform3(-2.0f32..2.0),
        prop::collection::vec((prop::array::uniform3(-1.0f32..1.0), 0.05f32..1.0), 1..60),
    )
        .prop_map(|(o, dirs)| {
            let pts = dirs
                .iter()
                .map(|(d, s)| [o[0] + d[0] * s * 2.5, o[1] + d[1] * s * 2.5, o[2] + d[2] * s * 2.5])
                .collect();
            (o, pts)
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// Random scans from random origins (negative keys, chunk borders, clipped rays): the map
    /// equals the brute-force reference, and its boxes are exactly its occupied voxels.
    #[test]
    fn a_scan_matches_the_reference((origin, points) in scan_strategy(), link_at in prop::array::uniform3(-2.0f64..2.0)) {
        let config = MapConfig { resolution: 0.05, max_range: 1.5, ..MapConfig::default() };
        let robot = [Primitive::new(Shape::Sphere { radius: 0.4 }, Isometry3::translation(link_at[0], link_at[1], link_at[2]))];
        let mut m = map(config.clone());
        m.insert_cloud(&origin, &points, &robot);
        let want = reference(&config, &origin, &points, &robot);
        let got: BTreeMap<Key, Occupancy> = m.known().into_iter().map(|(k, _)| (k, m.state(&k))).collect();
        prop_assert_eq!(&got, &want);
        // Marked in the chunks directly (the path of scans too large for the dense grid): the same.
        let mut sparse = map(config.clone());
        sparse.set_dense_limit(0);
        sparse.insert_cloud(&origin, &points, &robot);
        prop_assert_eq!(sparse.known(), m.known());
        let occupied: BTreeSet<Key> = want.iter().filter(|(_, s)| **s == Occupancy::Occupied).map(|(k, _)| *k).collect();
        let mut boxed = BTreeSet::new();
        for b in m.boxes() {
            for x in b.min[0]..=b.max[0] {
                for y in b.min[1]..=b.max[1] {
                    for z in b.min[2]..=b.max[2] {
                        prop_assert!(boxed.insert([x, y, z]));
                    }
                }
            }
        }
        prop_assert_eq!(boxed, occupied.clone());
        // Each occupied voxel's centre collides; with no padding a point whose 27 voxels
        // around are all not occupied does not.
        let g = *m.grid();
        for k in &occupied {
            prop_assert!(m.collides_point(&p(g.center(k[0]), g.center(k[1]), g.center(k[2]))));
        }
        let bare = {
            let mut b = map(MapConfig { padding: 0.0, ..config.clone() });
            b.insert_cloud(&origin, &points, &robot);
            b
        };
        for q in points.iter().take(10) {
            let c = [q[0] as f64 + 0.07, q[1] as f64, q[2] as f64];
            let kc = g.key64(&c).unwrap();
            let near = (-1..=1).any(|dx| (-1..=1).any(|dy| (-1..=1).any(|dz| occupied.contains(&[kc[0] + dx, kc[1] + dy, kc[2] + dz]))));
            if !near {
                prop_assert!(!bare.collides_point(&p(c[0], c[1], c[2])));
            }
        }
    }

    /// Same scans, same map and scene bytes; scans in two maps agree whatever else was seen.
    #[test]
    fn updates_are_deterministic(scans in prop::collection::vec(scan_strategy(), 1..4)) {
        let config = MapConfig { resolution: 0.05, max_range: 1.5, ..MapConfig::default() };
        let run = || {
            let mut m = map(config.clone());
            for (o, pts) in &scans {
                m.insert_cloud(o, pts, &[]);
            }
            (m.known().iter().map(|(k, l)| (*k, l.to_bits())).collect::<Vec<_>>(), m.planning_scene(Header::default(), 0.01).to_cdr())
        };
        prop_assert_eq!(run(), run());
    }
}

fn depth_image(z: f32, stamp: i64) -> Image {
    Image {
        header: Header { stamp: Time::from_nanos(stamp), frame_id: "camera_color_optical_frame".into() },
        width: W as u32,
        height: H as u32,
        encoding: "32FC1".into(),
        step: (W * 4) as u32,
        data: (0..W * H).flat_map(|_| z.to_le_bytes()).collect(),
        ..Default::default()
    }
}

#[test]
fn the_node_turns_depth_frames_into_a_planning_scene() {
    let mut bus = Bus::default();
    let mut node = DepthMapper::new(MapperConfig::default()).unwrap();
    // A depth frame before CameraInfo and TF: skipped, said on the status topic.
    bus.publish(DEPTH, 1, &depth_image(1.0, 1));
    node.step(1, &mut bus).unwrap();
    assert_eq!((node.frames, node.skipped), (0, 1));
    let status = FmuStatus::from_cdr(&bus.latest(STATUS).unwrap().cdr).unwrap();
    assert!(status.message.contains("no CameraInfo"), "{}", status.message);
    let info = CameraInfo {
        header: Header { frame_id: "camera_color_optical_frame".into(), ..Default::default() },
        width: W as u32,
        height: H as u32,
        k: [50.0, 0.0, 32.0, 0.0, 50.0, 24.0, 0.0, 0.0, 1.0],
        ..Default::default()
    };
    bus.publish(CAMERA_INFO, 2, &info);
    bus.publish(DEPTH, 2, &depth_image(1.0, 2));
    node.step(2, &mut bus).unwrap();
    let status = FmuStatus::from_cdr(&bus.latest(STATUS).unwrap().cdr).unwrap();
    assert!(status.message.contains("no TF from camera_color_optical_frame to map"), "{}", status.message);
    assert!(bus.latest(SCENE).is_none());
    // The camera 1 m up, looking along the map's +x (optical z forward, x right, y down).
    let r = UnitQuaternion::from_basis_unchecked(&[
        V3::new(0.0, -1.0, 0.0),
        V3::new(0.0, 0.0, -1.0),
        V3::new(1.0, 0.0, 0.0),
    ]);
    let cam = Isometry3::from_parts(Translation3::new(0.005, 0.0, 1.0), r);
    bus.publish(TF, 3, &tf("map", "camera_color_optical_frame", &cam));
    bus.publish(DEPTH, 3, &depth_image(1.0, 3));
    node.step(3, &mut bus).unwrap();
    assert_eq!(node.frames, 1);
    let scene = PlanningScene::from_cdr(&bus.latest(SCENE).unwrap().cdr).unwrap();
    assert_eq!(scene.header.frame_id, "map");
    assert_eq!(scene.header.stamp, Time::from_nanos(3));
    assert!(!scene.objects.is_empty());
    // The wall stands at x = 1.005 m: every box is in the layer 1.00..1.01 m.
    for o in &scene.objects {
        let (c, d) = (o.pose.position, &o.primitive.dimensions);
        assert!((c.x - d[0] / 2.0 - 1.0).abs() < 1e-9 && (c.x + d[0] / 2.0 - 1.01).abs() < 1e-9, "{o:?}");
    }
    assert!(node.map().collides_sphere(&p(0.97, 0.0, 1.0), 0.03));
    // The fruit allowed: its voxels leave the next scene.
    node.set_allowed(vec![Sphere { center: p(1.035, 0.0, 1.0), radius: 0.03 }]);
    let n = node.planning_scene(Time::default()).objects.len();
    let covered =
        |s: &PlanningScene| s.objects.iter().map(|o| o.primitive.dimensions.iter().product::<f64>()).sum::<f64>();
    assert!(covered(&node.planning_scene(Time::default())) < covered(&scene) && n > 0);
}
