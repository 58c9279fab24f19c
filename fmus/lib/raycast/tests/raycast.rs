//! The BVH caster must agree exactly with a brute-force scan over all objects.

use agrisim_math::Rng;
use agrisim_raycast::{cast_brute_force, Occluders, RayCaster, RigidPose};
use agrisim_scene::{generate, GreenhouseConfig, Kind, Object, Placement, Shape};

mod common;
use common::{random_solids, unit};

fn random_dir(rng: &mut Rng) -> [f64; 3] {
    unit([rng.scene_normal(), rng.scene_normal(), rng.scene_normal()])
}

fn small_scene() -> (GreenhouseConfig, Vec<Object>) {
    let cfg = GreenhouseConfig::from_toml_str(
        "rows = 4\nactive_rows = 3\nrow_length = 6.0\nlength = 14.0\nwidth = 14.0\nrandom_obstacles = 3\n\
         [[obstacles]]\nx = 8.0\ny = 5.0\nsize_x = 0.5\nsize_y = 0.4\nheight = 0.8\n",
    )
    .unwrap();
    let objs = generate(&cfg, 7).objects;
    (cfg, objs)
}

#[test]
fn bvh_equals_brute_force_on_random_rays() {
    let (cfg, objs) = small_scene();
    let rc = RayCaster::new(&objs);
    let mut rng = Rng::scene(42);
    let mut hits = 0;
    for k in 0..20_000 {
        // Mix of origins: anywhere in the hall, and LiDAR-like ones in the aisles.
        let o = if k % 2 == 0 {
            [rng.range(-1.0, cfg.length + 1.0), rng.range(-1.0, cfg.width + 1.0), rng.range(-0.5, cfg.height + 0.5)]
        } else {
            [rng.range(cfg.headland, cfg.headland + cfg.row_length), rng.range(0.0, cfg.width), rng.range(0.2, 2.0)]
        };
        let d = random_dir(&mut rng);
        let (tmin, tmax) = (rng.range(0.0, 0.2), rng.range(0.5, 60.0));
        let a = rc.cast(o, d, tmin, tmax, &[]);
        let b = cast_brute_force(&objs, o, d, tmin, tmax);
        match (a, b) {
            (None, None) => {}
            (Some(a), Some(b)) => {
                hits += 1;
                assert!((a.distance - b.distance).abs() <= 1e-9, "ray {k}: {a:?} vs {b:?}");
                assert_eq!(a.object, b.object, "ray {k}");
                assert_eq!(a.normal, b.normal, "ray {k}");
            }
            _ => panic!("ray {k} from {o:?} dir {d:?}: bvh {a:?} vs brute force {b:?}"),
        }
    }
    assert!(hits > 10_000, "only {hits} hits");
}

#[test]
fn axis_aligned_rays_agree_too() {
    // Axis-aligned directions hit the zero-component paths of the slab tests.
    let (cfg, objs) = small_scene();
    let rc = RayCaster::new(&objs);
    let mut rng = Rng::scene(3);
    let dirs =
        [[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
    for k in 0..6000 {
        let o = [rng.range(0.0, cfg.length), rng.range(0.0, cfg.width), rng.range(0.0, 3.0)];
        let d = dirs[k % 6];
        let a = rc.cast(o, d, 0.0, 100.0, &[]);
        let b = cast_brute_force(&objs, o, d, 0.0, 100.0);
        assert_eq!(a.map(|h| (h.object, h.distance)), b.map(|h| (h.object, h.distance)), "ray {k}");
    }
}

#[test]
fn dynamic_objects_are_hit() {
    let (_, objs) = small_scene();
    let rc = RayCaster::new(&objs);
    let robot = Object {
        id: 1_000_000,
        name: "robot/base".into(),
        kind: Kind::Robot,
        shape: Shape::Box { half: [0.6, 0.45, 0.3] },
        placement: Placement::at(2.0, 7.0, 0.3),
    };
    let h = rc.cast([0.5, 7.0, 0.3], [1.0, 0.0, 0.0], 0.0, 50.0, std::slice::from_ref(&robot)).unwrap();
    assert_eq!(h.object, 1_000_000);
    assert!((h.distance - 0.9).abs() < 1e-12);
    assert_eq!(h.normal, [-1.0, 0.0, 0.0]);
}

fn one(shape: Shape, placement: Placement) -> Vec<Object> {
    vec![Object { id: 0, name: "o".into(), kind: Kind::Obstacle, shape, placement }]
}

#[test]
fn analytic_distances() {
    let s = one(Shape::Sphere { radius: 0.5 }, Placement::at(3.0, 0.0, 0.0));
    let h = RayCaster::new(&s).cast([0.0; 3], [1.0, 0.0, 0.0], 0.0, 10.0, &[]).unwrap();
    assert!((h.distance - 2.5).abs() < 1e-12 && h.normal == [-1.0, 0.0, 0.0]);
    // From inside: the exit point.
    let h = RayCaster::new(&s).cast([3.0, 0.0, 0.0], [1.0, 0.0, 0.0], 0.0, 10.0, &[]).unwrap();
    assert!((h.distance - 0.5).abs() < 1e-12);

    // Upright cylinder: side and cap.
    let c = one(Shape::Cylinder { radius: 0.2, half_height: 1.0 }, Placement::at(2.0, 0.0, 1.0));
    let rc = RayCaster::new(&c);
    let h = rc.cast([0.0, 0.0, 0.5], [1.0, 0.0, 0.0], 0.0, 10.0, &[]).unwrap();
    assert!((h.distance - 1.8).abs() < 1e-12);
    let h = rc.cast([2.05, 0.0, 5.0], [0.0, 0.0, -1.0], 0.0, 10.0, &[]).unwrap();
    assert!((h.distance - 3.0).abs() < 1e-12 && (h.normal[2] - 1.0).abs() < 1e-12);
    assert!(rc.cast([2.25, 0.0, 5.0], [0.0, 0.0, -1.0], 0.0, 10.0, &[]).is_none());

    // Box yawed 45 deg: corner toward the ray at distance 2 - sqrt(2) * 0.5.
    let b = one(Shape::Box { half: [0.5, 0.5, 0.5] }, Placement::yawed([2.0, 0.0, 0.0], std::f64::consts::FRAC_PI_4));
    let h = RayCaster::new(&b).cast([0.0, 0.0, 0.1], [1.0, 0.0, 0.0], 0.0, 10.0, &[]).unwrap();
    assert!((h.distance - (2.0 - 0.5 * 2f64.sqrt())).abs() < 1e-12, "{h:?}");
    // Range limits.
    assert!(RayCaster::new(&b).cast([0.0, 0.0, 0.1], [1.0, 0.0, 0.0], 0.0, 1.0, &[]).is_none());
}

#[test]
fn empty_scene_casts_nothing() {
    let rc = RayCaster::new(&[]);
    assert!(rc.cast([0.0; 3], [1.0, 0.0, 0.0], 0.0, 10.0, &[]).is_none());
}

/// Exact-on-the-surface signed distance bound (max form): < 0 inside, 0 on the surface.
fn sdf(o: &Object, p: [f64; 3]) -> f64 {
    let m = o.placement.matrix();
    let c = o.placement.translation;
    let v = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
    let l = [
        m[0][0] * v[0] + m[1][0] * v[1] + m[2][0] * v[2],
        m[0][1] * v[0] + m[1][1] * v[1] + m[2][1] * v[2],
        m[0][2] * v[0] + m[1][2] * v[1] + m[2][2] * v[2],
    ];
    match o.shape {
        Shape::Sphere { radius } => (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt() - radius,
        Shape::Box { half } => (l[0].abs() - half[0]).max(l[1].abs() - half[1]).max(l[2].abs() - half[2]),
        Shape::Cylinder { radius, half_height } => {
            ((l[0] * l[0] + l[1] * l[1]).sqrt() - radius).max(l[2].abs() - half_height)
        }
    }
}

#[test]
fn random_solids_match_brute_force_and_geometry() {
    let mut rng = Rng::scene(11);
    let objs = random_solids(&mut rng, 400);
    let rc = RayCaster::new(&objs);
    let mut hits = 0;
    for k in 0..10_000 {
        let o = [rng.range(-1.0, 11.0), rng.range(-1.0, 11.0), rng.range(-1.0, 11.0)];
        let d = random_dir(&mut rng);
        let a = rc.cast(o, d, 0.0, 30.0, &[]);
        let b = cast_brute_force(&objs, o, d, 0.0, 30.0);
        assert_eq!(a, b, "ray {k}");
        let outside = objs.iter().all(|s| sdf(s, o) > 0.0);
        match a {
            Some(h) => {
                hits += 1;
                let p = [o[0] + h.distance * d[0], o[1] + h.distance * d[1], o[2] + h.distance * d[2]];
                let s = &objs[h.object as usize];
                assert!(sdf(s, p).abs() < 1e-9, "ray {k}: hit point off the surface by {}", sdf(s, p));
                let nn = h.normal.iter().map(|x| x * x).sum::<f64>().sqrt();
                assert!((nn - 1.0).abs() < 1e-9, "normal not unit");
                // Outward: a step along the normal leaves the solid.
                let q = [p[0] + 1e-6 * h.normal[0], p[1] + 1e-6 * h.normal[1], p[2] + 1e-6 * h.normal[2]];
                assert!(sdf(s, q) > 0.0, "ray {k}: normal points inward");
                if outside {
                    // Nothing solid between the origin and the hit (sampled).
                    for j in 0..50 {
                        let t = h.distance * (j as f64 + 0.5) / 50.0 - 1e-7;
                        let x = [o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]];
                        assert!(objs.iter().all(|s| sdf(s, x) > 0.0), "ray {k}: solid before the hit at t = {t}");
                    }
                }
            }
            None if outside => {
                for j in 0..100 {
                    let t = 30.0 * (j as f64 + 0.5) / 100.0;
                    let x = [o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]];
                    assert!(objs.iter().all(|s| sdf(s, x) > 0.0), "ray {k}: missed a solid at t = {t}");
                }
            }
            None => {}
        }
    }
    assert!(hits > 3000, "{hits}");
}

/// The shadow query against its reference: a walk from hit to hit with `cast`, restarting
/// 0.1 mm past each translucent surface, as the camera computed shadows before the query
/// existed. Rays toward random sun directions from points in the canopy and on the floor of
/// the default greenhouse, with the robot's base box as a mover.
#[test]
fn pass_through_equals_the_hit_to_hit_walk() {
    let cfg = GreenhouseConfig::default();
    let objs = generate(&cfg, cfg.seed).objects;
    let rc = RayCaster::new(&objs);
    let kind = |id: u32| objs.get(id as usize).map_or(Kind::Robot, |o| o.kind);
    let opaque = |id: u32| !matches!(kind(id), Kind::Wall | Kind::Roof);
    let base = Object {
        id: objs.len() as u32,
        name: "base".into(),
        kind: Kind::Robot,
        shape: Shape::Box { half: [0.6, 0.45, 0.3] },
        placement: Placement::yawed([6.0, 3.0, 0.5], 0.3),
    };
    let movers = RayCaster::new(std::slice::from_ref(&base));
    let walk = |mut p: [f64; 3], s: [f64; 3]| -> Option<u32> {
        let mut n = 0;
        for _ in 0..16 {
            match rc.cast(p, s, 1e-6, 1000.0, std::slice::from_ref(&base)) {
                None => return Some(n),
                Some(h) if opaque(h.object) => return None,
                Some(h) => {
                    n += 1;
                    let t = h.distance + 1e-4;
                    p = [p[0] + t * s[0], p[1] + t * s[1], p[2] + t * s[2]];
                }
            }
        }
        None
    };
    let mut rng = Rng::scene(9);
    let (mut lit, mut differ) = (0, 0);
    let n = 50_000;
    for k in 0..n {
        let p = [rng.range(0.0, cfg.length), rng.range(0.0, cfg.width), rng.range(0.0, 3.0)];
        let s = unit([rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(0.05, 1.0)]);
        let a = rc.pass_through(p, s, 1e-6, 1000.0, &movers, opaque);
        let b = walk(p, s);
        lit += a.is_some() as usize;
        if a != b {
            differ += 1;
            eprintln!("ray {k} from {p:?} toward {s:?}: query {a:?}, walk {b:?}");
        }
    }
    eprintln!("{lit} of {n} rays reach the sky, {differ} differ from the walk");
    assert!(lit > n / 10, "only {lit} lit");
    assert_eq!(differ, 0);

    // Packets: one sun direction, origins spread over a patch of canopy (a camera tile's
    // surface points), every answer equal to the single-ray query.
    let (mut blocked, mut through) = (0, 0);
    // The cached query with one cache across all packets (its occluders mostly miss a new
    // packet: the answers must not depend on them).
    let mut recent = Occluders::default();
    for k in 0..400 {
        let s = unit([rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(0.05, 1.0)]);
        let c = [rng.range(0.0, cfg.length), rng.range(0.0, cfg.width), rng.range(0.0, 3.0)];
        let size = [0.05, 0.5, 3.0][k % 3];
        let m = 1 + k % 64;
        let origins: Vec<[f64; 3]> = (0..m).map(|_| [0, 1, 2].map(|a| c[a] + rng.range(-size, size))).collect();
        let mut out = vec![None; m];
        rc.pass_through_packet(&origins, s, 1e-6, 1000.0, &movers, opaque, &mut out);
        // Twice through the cache: the second time its newest occluder is this packet's own.
        let mut cached = vec![None; m];
        for _ in 0..2 {
            rc.pass_through_cached(&origins, s, 1e-6, 1000.0, &movers, opaque, &mut recent, &mut cached);
            assert_eq!(cached, out, "packet {k}, cached");
        }
        for (i, o) in origins.iter().enumerate() {
            assert_eq!(out[i], rc.pass_through(*o, s, 1e-6, 1000.0, &movers, opaque), "packet {k} ray {i}");
            blocked += out[i].is_none() as usize;
            through += out[i].is_some_and(|n| n > 0) as usize;
        }
    }
    assert!(blocked > 100 && through > 1000, "{blocked} blocked, {through} through glass");
    assert!(recent.held() > 0, "no occluder remembered");
    // A cache filled on one scene and used with another: its entries name other primitives
    // there (here a pane of glass where an opaque slab was), and the answers stay exact.
    let slab = |id: u32, kind: Kind| Object {
        id,
        name: "slab".into(),
        kind,
        shape: Shape::Box { half: [1.0, 1.0, 0.01] },
        placement: Placement::yawed([0.0, 0.0, 2.0], 0.0),
    };
    let (roof, glass) = (RayCaster::new(&[slab(0, Kind::Obstacle)]), RayCaster::new(&[slab(0, Kind::Roof)]));
    let nothing = RayCaster::new(&[]);
    let below: Vec<[f64; 3]> = (0..8).map(|i| [0.1 * i as f64 - 0.4, 0.0, 0.5]).collect();
    let (mut reused, mut out) = (Occluders::default(), vec![None; 8]);
    roof.pass_through_cached(&below, [0.0, 0.0, 1.0], 1e-6, 1000.0, &nothing, |_| true, &mut reused, &mut out);
    assert!(out.iter().all(Option::is_none) && reused.held() == 1, "{out:?}");
    let through_glass = |id: u32| id != 0;
    glass.pass_through_cached(&below, [0.0, 0.0, 1.0], 1e-6, 1000.0, &nothing, through_glass, &mut reused, &mut out);
    assert_eq!(out, vec![Some(2); 8], "the remembered slab is glass here");
}

/// Packets (camera tiles of up to 64 rays from one origin) give exactly the single-ray
/// answers: on the default greenhouse from aisle points looking every way (tiles straddling
/// an axis fall back to single rays), and on random tilted solids.
#[test]
fn packets_equal_single_rays() {
    use agrisim_raycast::MAX_PACKET;
    let cfg = GreenhouseConfig::default();
    let gh = generate(&cfg, cfg.seed);
    let mut rng = Rng::scene(4);
    let solids = random_solids(&mut rng, 300);
    let base = Object {
        id: 1_000_000,
        name: "base".into(),
        kind: Kind::Robot,
        shape: Shape::Box { half: [0.6, 0.45, 0.3] },
        placement: Placement::yawed([6.0, 3.0, 0.5], 0.3),
    };
    let movers = RayCaster::new(std::slice::from_ref(&base));
    // A robot in its own frame, placed per ray by a pose.
    let local = RayCaster::new(&[Object { id: 1_000_001, placement: Placement::at(0.0, 0.0, 0.5), ..base.clone() }]);
    let (mut packets, mut hits, mut posed_hits, mut beyond_hits) = (0, 0, 0, 0);
    let (mut coherent_posed_hits, mut mixed_signs) = (0, 0);
    for (objs, origins) in [(&gh.objects, 0), (&solids, 1)] {
        let rc = RayCaster::new(objs);
        for k in 0..300 {
            let o = if origins == 0 {
                let a = &gh.layout.aisles[k % gh.layout.aisles.len()];
                [rng.range(a.x_start, a.x_end), a.y + rng.range(-0.5, 0.5), rng.range(0.3, 2.5)]
            } else {
                [rng.range(-1.0, 11.0), rng.range(-1.0, 11.0), rng.range(-1.0, 11.0)]
            };
            // A tile: a random central direction and a spread from a pixel's width to wide (the
            // widest often straddles an axis: the posed cast then splits it by octant).
            let c = random_dir(&mut rng);
            let spread = [0.0005, 0.005, 0.05, 0.3][k % 4];
            let n = 1 + k % MAX_PACKET;
            let dirs: Vec<[f64; 3]> = (0..n)
                .map(|_| {
                    unit([
                        c[0] + spread * rng.range(-1.0, 1.0),
                        c[1] + spread * rng.range(-1.0, 1.0),
                        c[2] + spread * rng.range(-1.0, 1.0),
                    ])
                })
                .collect();
            let (tmin, tmax) = (rng.range(0.0, 0.2), rng.range(0.5, 60.0));
            let mut out = vec![None; n];
            rc.cast_packet(o, &dirs, tmin, tmax, &movers, &mut out);
            packets += 1;
            for (i, d) in dirs.iter().enumerate() {
                let single = rc.cast_among(o, *d, tmin, tmax, &movers);
                assert_eq!(out[i], single, "packet {k} ray {i} from {o:?} along {d:?}");
                hits += single.is_some() as usize;
            }
            // Each ray going on from its own near limit (past a pane it met): the single ray
            // cast from that limit.
            let mins: Vec<f64> =
                out.iter().map(|h| h.map_or(rng.range(0.0, 1.0), |h| h.distance + [1e-4, 0.0, -1e-3][k % 3])).collect();
            let mut beyond = vec![None; n];
            rc.cast_packet_beyond(o, &dirs, &mins, tmax, &movers, &mut beyond);
            for i in 0..n {
                assert_eq!(
                    beyond[i],
                    rc.cast_among(o, dirs[i], mins[i], tmax, &movers),
                    "packet {k} ray {i} beyond {}",
                    mins[i]
                );
                beyond_hits += (beyond[i].is_some() && beyond[i] != out[i]) as usize;
            }
            // Own origins (a moving LiDAR: up to 5 cm apart) and own mover poses.
            let origins: Vec<[f64; 3]> = (0..n).map(|_| [0, 1, 2].map(|a| o[a] + rng.range(-0.05, 0.05))).collect();
            // Poses all over (the rays' directions in the robot's frame then differ in sign:
            // single rays), or a base that moved a little between firings (one packet).
            let poses: Vec<RigidPose> = match k % 2 {
                0 => (0..n)
                    .map(|_| {
                        RigidPose::yawed(
                            o[0] + rng.range(-1.0, 1.0),
                            o[1] + rng.range(-1.0, 1.0),
                            0.0,
                            rng.range(-3.0, 3.0),
                        )
                    })
                    .collect(),
                _ => {
                    let (x, y, yaw) = (o[0] + rng.range(-1.0, 1.0), o[1] + rng.range(-1.0, 1.0), rng.range(-3.0, 3.0));
                    (0..n)
                        .map(|_| {
                            RigidPose::yawed(
                                x + rng.range(-0.02, 0.02),
                                y + rng.range(-0.02, 0.02),
                                0.0,
                                yaw + rng.range(-0.01, 0.01),
                            )
                        })
                        .collect()
                }
            };
            mixed_signs += (0..3).any(|a| dirs.iter().any(|d| d[a] > 0.0) && dirs.iter().any(|d| d[a] < 0.0)) as usize;
            // No movers at all (the scene alone).
            rc.cast_packet_posed(
                &origins,
                &dirs,
                tmin,
                tmax,
                &RayCaster::new(&[]),
                &RayCaster::new(&[]),
                &poses,
                &mut out,
            );
            for i in 0..n {
                assert_eq!(
                    out[i],
                    rc.cast(origins[i], dirs[i], tmin, tmax, &[]),
                    "posed packet {k} ray {i} without movers"
                );
            }
            rc.cast_packet_posed(&origins, &dirs, tmin, tmax, &RayCaster::new(&[]), &local, &poses, &mut out);
            for i in 0..n {
                let single = rc.cast_among_posed(origins[i], dirs[i], tmin, tmax, &local, &poses[i]);
                assert_eq!(out[i], single, "posed packet {k} ray {i}");
                posed_hits += single.is_some_and(|h| h.object == 1_000_001) as usize;
                coherent_posed_hits += (k % 2 == 1 && single.is_some_and(|h| h.object == 1_000_001)) as usize;
            }
        }
    }
    assert!(
        packets == 600 && hits > 5_000 && coherent_posed_hits > 25 && posed_hits > 50 && beyond_hits > 1_000 && mixed_signs > 100,
        "{hits} hits, {posed_hits} on the posed robot ({coherent_posed_hits} from coherent poses), {beyond_hits} further hits beyond, {mixed_signs} packets with directions of both signs on an axis"
    );
}
