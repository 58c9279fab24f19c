//! Rasterization of known primitives into the occupancy grid.

use agrisim_scene::occupancy::OccupancyMap;
use agrisim_scene::scene::quat_axis_angle;
use agrisim_scene::{Kind, Object, Placement, Shape};

fn obj(shape: Shape, placement: Placement) -> Object {
    Object { id: 0, name: "o".into(), kind: Kind::Obstacle, shape, placement }
}

fn occupied(m: &OccupancyMap) -> Vec<(usize, usize)> {
    let mut v = Vec::new();
    for j in 0..m.height {
        for i in 0..m.width {
            if m.data[j * m.width + i] == 100 {
                v.push((i, j));
            }
        }
    }
    v
}

#[test]
fn geometry_of_the_grid() {
    let m = OccupancyMap::from_objects(&[], 0.05, (0.0, 1.0), [-1.0, 2.0, 3.0, 4.0]);
    assert_eq!((m.width, m.height, m.origin), (80, 40, [-1.0, 2.0]));
    assert_eq!(m.cell(-1.0, 2.0), Some((0, 0)));
    assert_eq!(m.cell(2.999, 3.999), Some((79, 39)));
    assert_eq!(m.cell(3.0, 3.0), None);
    assert_eq!(m.cell(-1.01, 3.0), None);
    assert!(m.is_occupied_at(10.0, 10.0), "outside counts as occupied");
    assert!(!m.is_occupied_at(0.0, 3.0));
}

#[test]
fn axis_aligned_box_fills_exactly_its_cells() {
    // Box x in [1.0, 1.5], y in [0.5, 0.75]: cells i 20..30, j 10..15 (cell size 0.05).
    let b = obj(Shape::Box { half: [0.25, 0.125, 0.5] }, Placement::at(1.25, 0.625, 0.5));
    let m = OccupancyMap::from_objects(&[b], 0.05, (0.1, 2.0), [0.0, 0.0, 3.0, 2.0]);
    let want: Vec<(usize, usize)> = (10..15).flat_map(|j| (20..30).map(move |i| (i, j))).collect();
    assert_eq!(occupied(&m), want);
    assert!(m.is_occupied_at(1.01, 0.51) && !m.is_occupied_at(0.99, 0.6) && !m.is_occupied_at(1.2, 0.76));
}

#[test]
fn z_band_filters() {
    let b = obj(Shape::Box { half: [0.25, 0.25, 0.25] }, Placement::at(1.0, 1.0, 3.0));
    assert_eq!(
        OccupancyMap::from_objects(std::slice::from_ref(&b), 0.05, (0.0, 2.0), [0.0, 0.0, 2.0, 2.0]).occupied_count(),
        0
    );
    assert_eq!(OccupancyMap::from_objects(&[b], 0.05, (0.0, 2.8), [0.0, 0.0, 2.0, 2.0]).occupied_count(), 100);
    // The floor slab's top face at z = 0 merely touches a band starting at 0.
    let floor = obj(Shape::Box { half: [5.0, 5.0, 0.1] }, Placement::at(1.0, 1.0, -0.1));
    assert_eq!(OccupancyMap::from_objects(&[floor], 0.05, (0.0, 2.0), [0.0, 0.0, 2.0, 2.0]).occupied_count(), 0);
}

#[test]
fn upright_cylinder_is_a_disc() {
    let r = 0.3;
    let c = obj(Shape::Cylinder { radius: r, half_height: 1.0 }, Placement::at(1.0, 1.0, 1.0));
    let m = OccupancyMap::from_objects(&[c], 0.05, (0.1, 0.5), [0.0, 0.0, 2.0, 2.0]);
    // A cell is occupied iff its square comes closer than r to the centre.
    for j in 0..m.height {
        for i in 0..m.width {
            let (x0, y0) = (i as f64 * 0.05, j as f64 * 0.05);
            let dx = (x0 - 1.0).max(0.0).max(1.0 - (x0 + 0.05));
            let dy = (y0 - 1.0).max(0.0).max(1.0 - (y0 + 0.05));
            let inside = dx * dx + dy * dy < r * r - 1e-9;
            assert_eq!(m.data[j * m.width + i] == 100, inside, "cell {i},{j}");
        }
    }
    // Area close to pi r^2 (plus the boundary ring of cells).
    let area = m.occupied_count() as f64 * 0.0025;
    assert!(area > std::f64::consts::PI * r * r && area < std::f64::consts::PI * (r + 0.071f64).powi(2), "{area}");
}

#[test]
fn horizontal_cylinder_is_a_band() {
    // A pipe along x at z = 0.1, r = 0.05: in band (0.0, 0.5) it covers y in [0.95, 1.05].
    let q = quat_axis_angle([0.0, 1.0, 0.0], std::f64::consts::FRAC_PI_2);
    let p = obj(
        Shape::Cylinder { radius: 0.05, half_height: 0.5 },
        Placement { translation: [1.0, 1.0, 0.1], rotation: q },
    );
    let m = OccupancyMap::from_objects(&[p], 0.05, (0.0, 0.5), [0.0, 0.0, 2.0, 2.0]);
    assert!(m.is_occupied_at(1.0, 1.0) && m.is_occupied_at(0.52, 1.04) && m.is_occupied_at(1.48, 0.96));
    assert!(!m.is_occupied_at(0.4, 1.0) && !m.is_occupied_at(1.6, 1.0) && !m.is_occupied_at(1.0, 1.12));
    // Rows j = 19, 20 (y 0.95..1.05) plus j = 18, 21: the circumscribed prism reaches
    // 1 mm past the true radius, into the neighbouring cells (conservative by design); i 10..30.
    assert_eq!(m.occupied_count(), 4 * 20);
    assert!(!m.is_occupied_at(1.0, 1.101) && !m.is_occupied_at(1.0, 0.899));
}

#[test]
fn sphere_cut_by_the_band() {
    // Sphere r = 0.5 at z = 1.0, band up to 0.6: the slice at z = 0.6 has radius 0.3.
    let s = obj(Shape::Sphere { radius: 0.5 }, Placement::at(1.0, 1.0, 1.0));
    let m = OccupancyMap::from_objects(&[s], 0.01, (0.0, 0.6), [0.0, 0.0, 2.0, 2.0]);
    assert!(m.is_occupied_at(1.29, 1.0) && !m.is_occupied_at(1.31, 1.0));
}

#[test]
fn rotated_box() {
    // 45 deg yawed square of half side 0.2: a diamond with vertices 0.283 from the centre.
    let b = obj(Shape::Box { half: [0.2, 0.2, 0.5] }, Placement::yawed([1.0, 1.0, 0.5], std::f64::consts::FRAC_PI_4));
    let m = OccupancyMap::from_objects(&[b], 0.01, (0.0, 2.0), [0.0, 0.0, 2.0, 2.0]);
    assert!(m.is_occupied_at(1.27, 1.0) && !m.is_occupied_at(1.29, 1.0));
    assert!(!m.is_occupied_at(1.16, 1.16) && m.is_occupied_at(1.13, 1.13));
}
