//! A scene with moved objects ([`MovedScene`]) must answer exactly as a scene built with those
//! objects at their new placements: single rays, camera-like packets, posed LiDAR packets and
//! shadow rays through the sun columns; and an object put back answers as never moved.

use agrisim_math::Rng;
use agrisim_raycast::cast_scene::CastScene;
use agrisim_raycast::{cast_brute_force, MovedScene, RayCaster, RigidPose, Shadow, SunColumns, MAX_PACKET};
use agrisim_scene::{generate, GreenhouseConfig, Kind, Object, Placement};

#[allow(dead_code)]
mod common;
use common::unit;

fn scene() -> (GreenhouseConfig, Vec<Object>) {
    let cfg =
        GreenhouseConfig::from_toml_str("rows = 3\nactive_rows = 3\nrow_length = 4.0\nlength = 10.0\nwidth = 10.0")
            .unwrap();
    let objects = generate(&cfg, 5).objects;
    (cfg, objects)
}

/// Some leaves and fruit moved by up to 0.3 m and turned: (id, placement), ids ascending.
fn moves(objects: &[Object], rng: &mut Rng, count: usize) -> Vec<(u32, Placement)> {
    let movable: Vec<&Object> = objects.iter().filter(|o| matches!(o.kind, Kind::Leaf | Kind::Fruit { .. })).collect();
    let mut out: Vec<(u32, Placement)> = (0..count)
        .map(|_| {
            let o = movable[(rng.uniform() * movable.len() as f64) as usize % movable.len()];
            let t = o.placement.translation;
            let q = unit4([rng.scene_normal(), rng.scene_normal(), rng.scene_normal(), rng.scene_normal()]);
            let shift = [rng.range(-0.3, 0.3), rng.range(-0.3, 0.3), rng.range(-0.3, 0.3)];
            (o.id, Placement { translation: [t[0] + shift[0], t[1] + shift[1], t[2] + shift[2]], rotation: q })
        })
        .collect();
    out.sort_by_key(|m| m.0);
    out.dedup_by_key(|m| m.0);
    out
}

fn unit4(q: [f64; 4]) -> [f64; 4] {
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    q.map(|v| v / n)
}

/// The objects with `moves` applied.
fn moved_objects(objects: &[Object], moves: &[(u32, Placement)]) -> Vec<Object> {
    let mut out = objects.to_vec();
    for &(id, p) in moves {
        out[id as usize].placement = p;
    }
    out
}

fn ray(cfg: &GreenhouseConfig, rng: &mut Rng) -> ([f64; 3], [f64; 3]) {
    let o = [rng.range(cfg.headland, cfg.headland + cfg.row_length), rng.range(0.0, cfg.width), rng.range(0.2, 2.0)];
    (o, unit([rng.scene_normal(), rng.scene_normal(), rng.scene_normal()]))
}

#[test]
fn moved_objects_are_cast_where_they_are_and_nowhere_else() {
    let (cfg, objects) = scene();
    let base = CastScene::from_objects(&objects);
    let mut view = MovedScene::default();
    let mut rng = Rng::scene(11);
    let mut moved_hits = 0;
    // Moves, then other moves (some kept, some put back), then none.
    for (round, count) in [(0, 40), (1, 25), (2, 0)] {
        let m = moves(&objects, &mut Rng::scene(100 + round), count);
        view.update(&base, &m);
        assert_eq!(view.len(), m.len());
        let truth = moved_objects(&objects, &m);
        let scene = view.scene(&base);
        let movers = RayCaster::new(&view.objects());
        for k in 0..6000 {
            let (o, mut d) = ray(&cfg, &mut rng);
            // Most rays aim at a moved object: where it is now, or where it grew.
            if !m.is_empty() && k % 4 != 0 {
                let (id, p) = m[k % m.len()];
                let at = if k % 4 == 1 { objects[id as usize].placement.translation } else { p.translation };
                d = unit([at[0] - o[0], at[1] - o[1], at[2] - o[2]]);
            }
            let got = scene.caster.cast_among(o, d, 0.0, 30.0, &movers);
            let want = cast_brute_force(&truth, o, d, 0.0, 30.0);
            assert_eq!(got.map(|h| h.object), want.map(|h| h.object), "round {round} ray {k}");
            if let (Some(g), Some(w)) = (got, want) {
                assert!((g.distance - w.distance).abs() < 1e-9, "round {round} ray {k}: {g:?} vs {w:?}");
                moved_hits += m.iter().any(|x| x.0 == g.object) as usize;
            }
        }
        // The shading detail follows the object.
        for &(id, p) in &m {
            assert_eq!(scene.geometry[id as usize].1, p);
        }
        if count == 0 {
            assert!(std::ptr::eq(scene, &base), "with nothing moved the shared scene is cast at");
        }
    }
    assert!(moved_hits > 1000, "only {moved_hits} rays met a moved object");
}

#[test]
fn camera_packets_and_posed_lidar_packets_agree_with_single_rays() {
    let (cfg, objects) = scene();
    let base = CastScene::from_objects(&objects);
    let mut view = MovedScene::default();
    let m = moves(&objects, &mut Rng::scene(7), 60);
    view.update(&base, &m);
    let scene = view.scene(&base);
    let placed = RayCaster::new(&view.objects());
    let none = RayCaster::new(&[]);
    let mut rng = Rng::scene(3);
    for k in 0..300 {
        let (o, d0) = ray(&cfg, &mut rng);
        // A coherent bundle around d0, as a camera tile's.
        let dirs: Vec<[f64; 3]> = (0..MAX_PACKET)
            .map(|_| {
                unit([d0[0] + rng.range(-0.05, 0.05), d0[1] + rng.range(-0.05, 0.05), d0[2] + rng.range(-0.05, 0.05)])
            })
            .collect();
        let mut out = vec![None; dirs.len()];
        scene.caster.cast_packet(o, &dirs, 0.0, 30.0, &placed, &mut out);
        for (i, d) in dirs.iter().enumerate() {
            assert_eq!(out[i], scene.caster.cast_among(o, *d, 0.0, 30.0, &placed), "packet {k} ray {i}");
        }
        let origins = vec![o; dirs.len()];
        let poses = vec![RigidPose::yawed(0.0, 0.0, 0.0, 0.0); dirs.len()];
        let mut posed = vec![None; dirs.len()];
        scene.caster.cast_packet_posed(&origins, &dirs, 0.0, 30.0, &placed, &none, &poses, &mut posed);
        assert_eq!(posed, out, "posed packet {k}");
    }
}

#[test]
fn shadow_columns_built_on_the_grown_scene_stay_exact_after_moves() {
    let (cfg, objects) = scene();
    let base = CastScene::from_objects(&objects);
    let sun = unit([0.3, -0.4, 0.8]);
    let opaque = |id: u32| !matches!(base.kind(id), Kind::Roof | Kind::Wall);
    let columns = SunColumns::new(&base.caster, sun, opaque, 0.05, 1 << 20).expect("the sun is high");
    let mut view = MovedScene::default();
    let m = moves(&objects, &mut Rng::scene(9), 80);
    view.update(&base, &m);
    let truth = moved_objects(&objects, &m);
    let scene = view.scene(&base);
    let mut rng = Rng::scene(5);
    let (mut blocked, mut checked) = (0, 0);
    for _ in 0..20_000 {
        let (p, _) = ray(&cfg, &mut rng);
        let want = truth
            .iter()
            .any(|o| opaque(o.id) && cast_brute_force(std::slice::from_ref(o), p, sun, 1e-6, 1e3).is_some());
        // The columns answer for the static tree alone (moved objects are cast as movers).
        let statics = match columns.occluder(&scene.caster, p, 1e-6, 1e3, None) {
            Shadow::Clear => false,
            Shadow::Blocked(_) => true,
            Shadow::Unknown => continue,
        };
        let moved_blocks = m.iter().any(|&(id, pl)| {
            let mut o = objects[id as usize].clone();
            o.placement = pl;
            opaque(id) && cast_brute_force(&[o], p, sun, 1e-6, 1e3).is_some()
        });
        assert_eq!(statics || moved_blocks, want, "shadow ray from {p:?}");
        checked += 1;
        blocked += want as usize;
    }
    assert!(checked > 1000 && blocked > 100, "{checked} checked, {blocked} blocked");
}
