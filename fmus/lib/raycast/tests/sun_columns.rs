//! Shadow grids ([`SunColumns`]) clear only rays that no opaque object stops: for every point
//! they clear, the whole scene's shadow query finds nothing opaque and their glass-and-film
//! tree gives its answer exactly. Their lists ([`SunColumns::occluder`]) say blocked exactly
//! when the scene's query does, whatever hint they are given. Points in the canopy, on
//! surfaces (as the camera's shadow rays start, 1 um off), and just above the tops of tilted
//! solids.

use agrisim_math::Rng;
use agrisim_raycast::{RayCaster, Shadow, SunColumns};
use agrisim_scene::{generate, GreenhouseConfig, Kind, Object, Placement, Shape};

mod common;
use common::{random_solids, unit};

/// Sun directions: random ones from 3 deg up, straight overhead and in the x-z and y-z
/// planes (a zero slope on one axis).
fn suns(rng: &mut Rng) -> Vec<[f64; 3]> {
    let mut s = vec![[0.0, 0.0, 1.0], unit([0.6, 0.0, 0.8]), unit([0.0, -0.5, 0.5])];
    s.extend((0..5).map(|_| unit([rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(0.06, 1.0)])));
    s
}

/// Checks `p` under `grid`: a cleared ray meets nothing opaque (from its very start) and the
/// glass-and-film tree answers as the whole scene does; the lists' answer (with no hint and
/// with `hint`, any index) is blocked exactly when the scene's query finds something opaque,
/// and a clear one gets the scene's answer from the glass-and-film tree. Returns whether the
/// columns cleared it and whether the lists found it blocked.
fn check(
    rc: &RayCaster,
    grid: &SunColumns,
    movers: &RayCaster,
    opaque: impl Fn(u32) -> bool + Copy,
    p: [f64; 3],
    hint: u32,
) -> (bool, bool) {
    let s = grid.dir();
    let nothing = RayCaster::new(&[]);
    let cleared = grid.clear(p);
    if cleared {
        assert!(
            rc.pass_through(p, s, 0.0, 1000.0, &nothing, opaque).is_some(),
            "{p:?} cleared toward {s:?}, but an opaque object blocks it"
        );
    }
    let scene = rc.pass_through(p, s, 1e-6, 1000.0, &nothing, opaque);
    let answer = grid.occluder(rc, p, 1e-6, 1000.0, None);
    for (with, a) in [(None, answer), (Some(hint), grid.occluder(rc, p, 1e-6, 1000.0, Some(hint)))] {
        match a {
            Shadow::Blocked(_) => {
                assert!(scene.is_none(), "{p:?} toward {s:?}: blocked by the lists (hint {with:?}), not by the scene")
            }
            Shadow::Clear => {
                assert!(
                    scene.is_some(),
                    "{p:?} toward {s:?}: clear by the lists (hint {with:?}), blocked in the scene"
                );
                assert_eq!(
                    grid.translucent().pass_through(p, s, 1e-6, 1000.0, movers, opaque),
                    rc.pass_through(p, s, 1e-6, 1000.0, movers, opaque),
                    "{p:?} toward {s:?}"
                );
            }
            Shadow::Unknown => panic!("{p:?}: a grid with lists answered unknown"),
        }
    }
    assert!(!cleared || answer == Shadow::Clear, "{p:?}: cleared by the columns, {answer:?} by the lists");
    (cleared, matches!(answer, Shadow::Blocked(_)))
}

#[test]
fn cleared_rays_meet_no_opaque_object_in_the_greenhouse() {
    let cfg = GreenhouseConfig::default();
    let objs = generate(&cfg, cfg.seed).objects;
    let rc = RayCaster::new(&objs);
    let opaque = |id: u32| objs.get(id as usize).is_none_or(|o| !matches!(o.kind, Kind::Wall | Kind::Roof));
    let base = Object {
        id: objs.len() as u32,
        name: "base".into(),
        kind: Kind::Robot,
        shape: Shape::Box { half: [0.6, 0.45, 0.3] },
        placement: Placement::yawed([6.0, 3.0, 0.5], 0.3),
    };
    let movers = RayCaster::new(std::slice::from_ref(&base));
    let mut rng = Rng::scene(5);
    // (cleared, tried) for points in the air and on surfaces; rays the lists found blocked.
    let (mut air, mut surface, mut blocked) = ((0, 0), (0, 0), 0);
    let hints = rc.len() as u32 + 10;
    for s in suns(&mut rng) {
        for cell in [0.05, 0.013] {
            let grid = SunColumns::new(&rc, s, opaque, cell, 1 << 22).expect("sun above 3 deg");
            for _ in 0..3000 {
                // A point in the air, and the surface point a random ray from it meets.
                let p = [rng.range(0.0, cfg.length), rng.range(0.0, cfg.width), rng.range(0.0, 4.0)];
                let d = unit([rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 0.3)]);
                air.1 += 1;
                let (c, b) = check(&rc, &grid, &movers, opaque, p, rng.below(hints as u64) as u32);
                (air.0, blocked) = (air.0 + c as usize, blocked + b as usize);
                if let Some(h) = rc.cast_among(p, d, 0.0, 100.0, &movers) {
                    let n = if h.normal[0] * d[0] + h.normal[1] * d[1] + h.normal[2] * d[2] > 0.0 {
                        h.normal.map(|v| -v)
                    } else {
                        h.normal
                    };
                    let q = [0, 1, 2].map(|a| p[a] + h.distance * d[a] + 1e-6 * n[a]);
                    surface.1 += 1;
                    let (c, b) = check(&rc, &grid, &movers, opaque, q, rng.below(hints as u64) as u32);
                    (surface.0, blocked) = (surface.0 + c as usize, blocked + b as usize);
                }
            }
        }
    }
    eprintln!(
        "cleared: {} of {} points in the air, {} of {} on surfaces; {blocked} blocked",
        air.0, air.1, surface.0, surface.1
    );
    assert!(air.0 > air.1 / 5 && surface.0 > surface.1 / 10, "cleared: air {air:?}, surfaces {surface:?}");
    assert!(blocked > (air.1 + surface.1) / 40, "only {blocked} blocked");
    assert!(
        SunColumns::new(&rc, unit([1.0, 0.0, 0.04]), opaque, 0.05, 1 << 22).is_none(),
        "no grid for a sun 2 deg up"
    );
}

#[test]
fn cleared_rays_meet_no_tilted_solid_from_just_above_its_top() {
    let mut rng = Rng::scene(21);
    // Every fourth a pane (translucent).
    let mut objs = random_solids(&mut rng, 300);
    objs.iter_mut().step_by(4).for_each(|o| o.kind = Kind::Roof);
    let rc = RayCaster::new(&objs);
    let opaque = |id: u32| objs[id as usize].kind != Kind::Roof;
    let nothing = RayCaster::new(&[]);
    let (mut cleared, mut tried) = (0, 0);
    for s in suns(&mut rng) {
        let grid = SunColumns::new(&rc, s, opaque, 0.02, 1 << 22).expect("sun above 3 deg");
        for o in &objs {
            let (mn, mx) = o.aabb();
            for lift in [0.0, 1e-12, 1e-9, 1e-7, 1e-6, 1e-3] {
                let p = [rng.range(mn[0], mx[0]), rng.range(mn[1], mx[1]), mx[2] + lift];
                tried += 1;
                cleared += check(&rc, &grid, &nothing, opaque, p, rng.below(objs.len() as u64 + 5) as u32).0 as usize;
            }
        }
    }
    eprintln!("{cleared} of {tried} points cleared");
    assert!(cleared > tried / 10, "only {cleared} of {tried} cleared");
}

#[test]
fn without_lists_or_for_another_scene_the_lists_do_not_answer() {
    let mut rng = Rng::scene(8);
    let objs = random_solids(&mut rng, 200);
    let rc = RayCaster::new(&objs);
    let all = |_: u32| true;
    let s = unit([0.3, -0.2, 0.9]);
    // 200 solids over at most 4 cells: more entries than the lists may hold.
    let coarse = SunColumns::new(&rc, s, all, 0.05, 4).expect("grid");
    let fine = SunColumns::new(&rc, s, all, 0.05, 1 << 20).expect("grid");
    let other = RayCaster::new(&objs[..150]);
    let mut unknown = 0;
    for _ in 0..2000 {
        let p = [rng.range(0.0, 10.0), rng.range(0.0, 10.0), rng.range(0.0, 10.0)];
        let cleared = coarse.clear(p);
        let a = coarse.occluder(&rc, p, 1e-6, 1000.0, None);
        assert!(
            if cleared { a == Shadow::Clear } else { a == Shadow::Unknown },
            "{p:?}: {a:?} from a grid without lists"
        );
        assert_eq!(fine.occluder(&other, p, 1e-6, 1000.0, None), Shadow::Unknown, "{p:?}: for another scene");
        assert_eq!(fine.occluder(&rc, p, -1.0, 1000.0, None), Shadow::Unknown, "{p:?}: a ray starting behind p");
        unknown += (a == Shadow::Unknown) as usize;
    }
    assert!(unknown > 100, "only {unknown} rays left unknown");
}
