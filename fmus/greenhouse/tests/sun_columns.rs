//! Shadow grids ([`SunColumns`]) clear only rays that no opaque object stops: for every point
//! they clear, the whole scene's shadow query finds nothing opaque and their glass-and-film
//! tree gives its answer exactly. Points in the canopy, on surfaces (as the camera's shadow
//! rays start, 1 um off), and just above the tops of tilted solids.

use agrisim_greenhouse::raycast::SunColumns;
use agrisim_greenhouse::{generate, GreenhouseConfig, Kind, Object, Placement, RayCaster, Shape};
use agrisim_math::Rng;

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
/// glass-and-film tree answers as the whole scene does. Returns whether it was cleared.
fn check(rc: &RayCaster, grid: &SunColumns, movers: &RayCaster, opaque: impl Fn(u32) -> bool + Copy, p: [f64; 3]) -> bool {
    let s = grid.dir();
    if !grid.clear(p) {
        return false;
    }
    let nothing = RayCaster::new(&[]);
    assert!(rc.pass_through(p, s, 0.0, 1000.0, &nothing, opaque).is_some(), "{p:?} cleared toward {s:?}, but an opaque object blocks it");
    assert_eq!(grid.translucent().pass_through(p, s, 1e-6, 1000.0, movers, opaque), rc.pass_through(p, s, 1e-6, 1000.0, movers, opaque), "{p:?} toward {s:?}");
    true
}

#[test]
fn cleared_rays_meet_no_opaque_object_in_the_greenhouse() {
    let cfg = GreenhouseConfig::default();
    let objs = generate(&cfg, cfg.seed).objects;
    let rc = RayCaster::new(&objs);
    let opaque = |id: u32| objs.get(id as usize).is_none_or(|o| !matches!(o.kind, Kind::Wall | Kind::Roof));
    let base = Object { id: objs.len() as u32, name: "base".into(), kind: Kind::Robot, shape: Shape::Box { half: [0.6, 0.45, 0.3] }, placement: Placement::yawed([6.0, 3.0, 0.5], 0.3) };
    let movers = RayCaster::new(std::slice::from_ref(&base));
    let mut rng = Rng::scene(5);
    // (cleared, tried) for points in the air and on surfaces.
    let (mut air, mut surface) = ((0, 0), (0, 0));
    for s in suns(&mut rng) {
        for cell in [0.05, 0.013] {
            let grid = SunColumns::new(&rc, s, opaque, cell, 1 << 22).expect("sun above 3 deg");
            for _ in 0..3000 {
                // A point in the air, and the surface point a random ray from it meets.
                let p = [rng.range(0.0, cfg.length), rng.range(0.0, cfg.width), rng.range(0.0, 4.0)];
                let d = unit([rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 0.3)]);
                air.1 += 1;
                air.0 += check(&rc, &grid, &movers, opaque, p) as usize;
                if let Some(h) = rc.cast_among(p, d, 0.0, 100.0, &movers) {
                    let n = if h.normal[0] * d[0] + h.normal[1] * d[1] + h.normal[2] * d[2] > 0.0 { h.normal.map(|v| -v) } else { h.normal };
                    let q = [0, 1, 2].map(|a| p[a] + h.distance * d[a] + 1e-6 * n[a]);
                    surface.1 += 1;
                    surface.0 += check(&rc, &grid, &movers, opaque, q) as usize;
                }
            }
        }
    }
    eprintln!("cleared: {} of {} points in the air, {} of {} on surfaces", air.0, air.1, surface.0, surface.1);
    assert!(air.0 > air.1 / 5 && surface.0 > surface.1 / 10, "cleared: air {air:?}, surfaces {surface:?}");
    assert!(SunColumns::new(&rc, unit([1.0, 0.0, 0.04]), opaque, 0.05, 1 << 22).is_none(), "no grid for a sun 2 deg up");
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
                cleared += check(&rc, &grid, &nothing, opaque, p) as usize;
            }
        }
    }
    eprintln!("{cleared} of {tried} points cleared");
    assert!(cleared > tried / 10, "only {cleared} of {tried} cleared");
}
