//! The greenhouse for viewers: `visualization_msgs/MarkerArray`s that RViz and Foxglove draw.
//!
//! Like the glTF export (`agrisim scene export`), this is the world side showing its own
//! scene to a person; it is not an input of any algorithm node (navigation, harvest and
//! perception never subscribe to these topics; tests/test_viewer_topics.py checks their
//! sources). Two latched topics, each published at the first instant and again only when it
//! changes:
//!
//! * [`SCENE_MARKERS`]: the static greenhouse (floor, walls, posts, gutters, heating pipes,
//!   obstacles, stems, leaves and trusses). The roof (it would hide everything from above)
//!   and the 4 mm pedicels are left out.
//! * [`FRUIT_MARKERS`]: the fruit, one sphere list per ripeness stage coloured from green
//!   (stage 1) to red (stage 6), at the positions the world reports on `/fruits` (so picked,
//!   carried, dropped and boxed fruit are drawn where they are). Kept apart from the static
//!   scene so that a moving fruit re-sends tens of kilobytes, not the whole greenhouse.
//!
//! Instanced: one marker per kind and primitive, never one per leaf. Cylinders (stems,
//! posts, pipes, trusses) are `LINE_LIST` segments along their axes, one marker per line
//! width (pedicels, 4 mm thick, are left out); each compound leaf is one `TRIANGLE_LIST`
//! triangle from the stem to its tip, as wide as its leaflets reach; other
//! boxes are `TRIANGLE_LIST` boxes (12 triangles each); fruit are `SPHERE_LIST`s. All in the
//! `map` frame.

use agrisim_bus::{Bus, Node};
use agrisim_error::Result;
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::geometry_msgs::{Point, PoseArray, Quaternion, Transform, TransformStamped, Vector3};
use agrisim_msgs::nav_msgs::Odometry;
use agrisim_msgs::std_msgs::{ColorRGBA, Header};
use agrisim_msgs::tf2_msgs::TFMessage;
use agrisim_msgs::visualization_msgs::{Marker, MarkerArray};
use agrisim_scene::generate::PEDICEL_RADIUS;
use agrisim_scene::{Greenhouse, Kind, Object, Placement, Shape};
use std::collections::BTreeMap;

/// The static greenhouse (visualization_msgs/MarkerArray, latched).
pub const SCENE_MARKERS: &str = "/scene/markers";
/// The fruit by ripeness (visualization_msgs/MarkerArray, latched, re-sent when fruit move).
pub const FRUIT_MARKERS: &str = "/scene/fruit_markers";
/// The world's fruit centres (geometry_msgs/PoseArray, fruit-list order).
pub const FRUITS: &str = "/fruits";
/// Frame of every marker.
pub const FRAME: &str = "map";
/// A fruit that moved more than this since the last fruit markers re-sends them \[m\].
pub const MOVE_THRESHOLD: f64 = 1e-3;

/// Fruit colours by USDA ripeness stage 1 (green) .. 6 (red), sRGB in \[0, 1\]; the same
/// progression the camera renders (green, breaker, turning, pink, light red, red).
pub const RIPENESS_COLOURS: [[f32; 3]; 6] = [
    [0.30, 0.62, 0.18],
    [0.62, 0.70, 0.25],
    [0.86, 0.66, 0.24],
    [0.93, 0.50, 0.36],
    [0.90, 0.30, 0.20],
    [0.78, 0.10, 0.08],
];

/// How one kind is drawn: namespace and colour.
fn style(kind: Kind) -> Option<(&'static str, [f32; 4])> {
    Some(match kind {
        Kind::Floor => ("floor", [0.55, 0.52, 0.47, 1.0]),
        Kind::Wall => ("walls", [0.85, 0.90, 0.95, 0.25]),
        Kind::Roof => return None,
        Kind::Post => ("posts", [0.62, 0.62, 0.65, 1.0]),
        Kind::Gutter => ("gutters", [0.72, 0.72, 0.75, 1.0]),
        Kind::HeatingPipe => ("pipes", [0.85, 0.85, 0.85, 1.0]),
        Kind::Stem => ("stems", [0.36, 0.55, 0.22, 1.0]),
        Kind::Leaf => ("leaves", [0.18, 0.48, 0.14, 1.0]),
        Kind::Truss => ("trusses", [0.42, 0.60, 0.26, 1.0]),
        Kind::Obstacle => ("obstacles", [0.85, 0.52, 0.18, 1.0]),
        Kind::Fruit { .. } | Kind::Robot => return None,
    })
}

/// Marker coordinates are rounded to this grid \[m\] (about 8 mm: within 4 mm on each axis,
/// under a tenth of a fruit's diameter and a sixth of a stem's; nothing a viewer at the
/// greenhouse's scale shows). A binary fraction, so the low mantissa bits are zero: the
/// coordinates of the default greenhouse (0 to 64 m) keep two informative bytes of eight, and
/// the recording's compression shrinks the markers to about a sixth. Against 1/512 m (2 mm),
/// with the level leaf edges (`leaf_triangle`) and the sorted fruit ([`FruitSet::markers`]),
/// the default greenhouse's markers compress 29 % smaller (105 to 74 kB; the fruit 47 to
/// 33 kB, the leaves 38 to 25 kB): `python/bench_viewer_size.py` measures them.
pub const GRID: f64 = 1.0 / 128.0;

fn point(p: [f64; 3]) -> Point {
    let q = |v: f64| (v / GRID).round() * GRID;
    Point { x: q(p[0]), y: q(p[1]), z: q(p[2]) }
}

fn colour(c: [f32; 4]) -> ColorRGBA {
    ColorRGBA::new(c[0], c[1], c[2], c[3])
}

fn marker(ns: &str, id: i32, ty: i32, scale: f64, rgba: [f32; 4], points: Vec<Point>, stamp: Time) -> Marker {
    Marker {
        header: Header { stamp, frame_id: FRAME.into() },
        ns: ns.into(),
        id,
        r#type: ty,
        action: Marker::ADD,
        scale: Vector3 { x: scale, y: scale, z: scale },
        color: colour(rgba),
        points,
        // Drawn with the latest transform of `map`, not the one at `stamp`: the greenhouse is
        // fixed in the map, and a viewer that joins later (the latched message is stamped at
        // the start) has no transform that old.
        frame_locked: true,
        ..Default::default()
    }
}

/// The 12 triangles of a box (outward winding), in the map frame.
fn box_triangles(half: [f64; 3], pl: &Placement, out: &mut Vec<Point>) {
    let c = |sx: f64, sy: f64, sz: f64| point(pl.transform_point([sx * half[0], sy * half[1], sz * half[2]]));
    // Each face: axis, sign; corners in counter-clockwise order seen from outside.
    for axis in 0..3 {
        for s in [-1.0, 1.0] {
            let corner = |u: f64, v: f64| {
                let mut k = [0.0; 3];
                k[axis] = s;
                k[(axis + 1) % 3] = u * s;
                k[(axis + 2) % 3] = v;
                c(k[0], k[1], k[2])
            };
            let (a, b, cc, d) = (corner(-1.0, -1.0), corner(1.0, -1.0), corner(1.0, 1.0), corner(-1.0, 1.0));
            out.extend([a, b, cc, a, cc, d]);
        }
    }
}

/// A compound leaf as one triangle: the apex at the petiole's base (on the stem), the far
/// edge level across the leaf's width at its tip (as wide as the leaflets reach from the
/// axis). `rachis` is the leaf's petiole and rachis (a cylinder from the base, local -z end,
/// toward the tip) and `leaflets` the corners of its leaflets' boxes. One triangle per leaf,
/// not per leaflet (ten times the bytes), keeps the leaves near 25 kB in a recording.
fn leaf_triangle(rachis: &Object, leaflets: &[[f64; 3]], out: &mut Vec<Point>) {
    let Shape::Cylinder { half_height, .. } = rachis.shape else { return };
    let base = rachis.placement.transform_point([0.0, 0.0, -half_height]);
    let end = rachis.placement.transform_point([0.0, 0.0, half_height]);
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let d = sub(end, base);
    let n = dot(d, d).sqrt();
    if n <= 0.0 {
        return;
    }
    let axis = d.map(|c| c / n);
    // Length: the farthest leaflet corner along the axis; width: the farthest across it.
    let (mut len, mut side, mut half_w) = (n, [0.0; 3], 0.0);
    for &c in leaflets {
        let v = sub(c, base);
        let along = dot(v, axis);
        len = f64::max(len, along);
        let perp = [v[0] - along * axis[0], v[1] - along * axis[1], v[2] - along * axis[2]];
        let w = dot(perp, perp).sqrt();
        if w > half_w {
            half_w = w;
            side = perp.map(|c| c / w);
        }
    }
    // The width is drawn level (across the axis, horizontal), as a tomato leaf's blade spreads,
    // unless the leaf points straight up or down. Both far corners then have one height: a
    // repeat the recording's compression takes for nearly free (a fifth fewer bytes for the
    // leaves than along the leaflets' own tilt).
    let level = [-axis[1], axis[0], 0.0];
    let l = dot(level, level).sqrt();
    if l > 1e-3 {
        side = level.map(|c| c / l);
    }
    let tip = [base[0] + len * axis[0], base[1] + len * axis[1], base[2] + len * axis[2]];
    let edge =
        |s: f64| point([tip[0] + s * half_w * side[0], tip[1] + s * half_w * side[1], tip[2] + s * half_w * side[2]]);
    out.extend([point(base), edge(-1.0), edge(1.0)]);
}

/// The 8 corners of a box in the map frame.
fn box_corners(half: [f64; 3], pl: &Placement) -> impl Iterator<Item = [f64; 3]> + '_ {
    (0..8).map(move |i| {
        let s = |b: usize| if i >> b & 1 == 1 { 1.0 } else { -1.0 };
        pl.transform_point([s(0) * half[0], s(1) * half[1], s(2) * half[2]])
    })
}

/// The two ends of a cylinder's axis.
fn cylinder_axis(half_height: f64, pl: &Placement) -> [Point; 2] {
    [point(pl.transform_point([0.0, 0.0, -half_height])), point(pl.transform_point([0.0, 0.0, half_height]))]
}

/// Line widths are grouped to the millimetre (one LINE_LIST marker per width).
fn width_key(radius: f64) -> i64 {
    (2000.0 * radius).round() as i64
}

/// The static greenhouse: every object but fruit, robot links and the roof, instanced by
/// kind and primitive. Deterministic: the same greenhouse gives the same bytes.
pub fn scene_markers(gh: &Greenhouse, stamp: Time) -> MarkerArray {
    // (ns, colour) -> triangles, and lines by width key.
    #[derive(Default)]
    struct Group {
        rgba: [f32; 4],
        triangles: Vec<Point>,
        lines: BTreeMap<i64, Vec<Point>>,
        spheres: BTreeMap<i64, Vec<Point>>,
    }
    let mut groups: BTreeMap<&'static str, Group> = BTreeMap::new();
    // A compound leaf is its rachis (a cylinder) followed by its leaflets (boxes).
    let mut leaf: Option<(&Object, Vec<[f64; 3]>)> = None;
    let mut leaves = Vec::new();
    for o in &gh.objects {
        let Some((ns, rgba)) = style(o.kind) else { continue };
        let g = groups.entry(ns).or_default();
        g.rgba = rgba;
        match (o.kind, o.shape) {
            (Kind::Leaf, Shape::Cylinder { .. }) => {
                if let Some((r, c)) = leaf.replace((o, Vec::new())) {
                    leaf_triangle(r, &c, &mut leaves);
                }
                continue;
            }
            (Kind::Leaf, Shape::Box { half }) if leaf.is_some() => {
                leaf.as_mut().expect("checked").1.extend(box_corners(half, &o.placement));
                continue;
            }
            _ => {}
        }
        match o.shape {
            // Pedicels (a 4 mm stalk per fruit) are left out: a fifth of the bytes, and too
            // thin to see at a viewer's distance.
            Shape::Cylinder { radius, .. } if o.kind == Kind::Truss && radius <= PEDICEL_RADIUS => {}
            Shape::Box { half } => box_triangles(half, &o.placement, &mut g.triangles),
            Shape::Cylinder { radius, half_height } => {
                g.lines.entry(width_key(radius)).or_default().extend(cylinder_axis(half_height, &o.placement))
            }
            Shape::Sphere { radius } => {
                g.spheres.entry(width_key(radius)).or_default().push(point(o.placement.translation))
            }
        }
    }
    if let Some((r, c)) = leaf {
        leaf_triangle(r, &c, &mut leaves);
    }
    if let Some(g) = groups.get_mut("leaves") {
        g.triangles.extend(leaves);
    }
    let mut markers = Vec::new();
    for (ns, g) in groups {
        let mut id = 0;
        if !g.triangles.is_empty() {
            markers.push(marker(ns, id, Marker::TRIANGLE_LIST, 1.0, g.rgba, g.triangles, stamp));
            id += 1;
        }
        for (w, points) in g.lines {
            markers.push(marker(ns, id, Marker::LINE_LIST, w as f64 / 1000.0, g.rgba, points, stamp));
            id += 1;
        }
        for (w, points) in g.spheres {
            markers.push(marker(ns, id, Marker::SPHERE_LIST, w as f64 / 1000.0, g.rgba, points, stamp));
            id += 1;
        }
    }
    MarkerArray { markers }
}

/// The fruit of a greenhouse: ripeness stage and radius per fruit, in fruit-list order (the
/// order of the world's `/fruits`: scene objects of kind Fruit by id).
#[derive(Clone, Debug, PartialEq)]
pub struct FruitSet {
    pub stage: Vec<u8>,
    pub radius: Vec<f64>,
    pub centre: Vec<[f64; 3]>,
}

impl FruitSet {
    pub fn of(gh: &Greenhouse) -> FruitSet {
        let fruit: Vec<&Object> = gh.objects.iter().filter(|o| matches!(o.kind, Kind::Fruit { .. })).collect();
        FruitSet {
            stage: fruit
                .iter()
                .map(|o| match o.kind {
                    Kind::Fruit { ripeness } => ripeness.clamp(1, 6),
                    _ => unreachable!("filtered to fruit"),
                })
                .collect(),
            radius: fruit.iter().map(|o| if let Shape::Sphere { radius } = o.shape { radius } else { 0.03 }).collect(),
            centre: fruit.iter().map(|o| o.placement.translation).collect(),
        }
    }

    /// One SPHERE_LIST per ripeness stage present (ns `fruit`, id = stage), its diameter the
    /// mean of that stage's fruit (a list has one size).
    pub fn markers(&self, stamp: Time) -> MarkerArray {
        let mut markers = Vec::new();
        for stage in 1..=6u8 {
            let idx: Vec<usize> = (0..self.stage.len()).filter(|&i| self.stage[i] == stage).collect();
            if idx.is_empty() {
                continue;
            }
            let d = 2.0 * idx.iter().map(|&i| self.radius[i]).sum::<f64>() / idx.len() as f64;
            let [r, g, b] = RIPENESS_COLOURS[stage as usize - 1];
            // Sorted across the rows, then along them and up (on the grid; ties keep the
            // fruit-list order): neighbours share coordinates, so the recording compresses the
            // lists 5 to 8 % smaller than in fruit-list order. A sphere list is a set: nothing
            // drawn changes.
            let mut points: Vec<Point> = idx.iter().map(|&i| point(self.centre[i])).collect();
            let cell = |v: f64| (v / GRID).round() as i64;
            points.sort_by_key(|p| (cell(p.y), cell(p.x), cell(p.z)));
            markers.push(marker("fruit", stage as i32, Marker::SPHERE_LIST, d, [r, g, b, 1.0], points, stamp));
        }
        MarkerArray { markers }
    }

    /// Takes the world's fruit centres; true when some fruit moved more than
    /// [`MOVE_THRESHOLD`] from `shown` (what the viewers have). A list of another length
    /// (another greenhouse) is ignored.
    fn update(&mut self, poses: &PoseArray) -> bool {
        if poses.poses.len() != self.centre.len() {
            return false;
        }
        for (c, p) in self.centre.iter_mut().zip(&poses.poses) {
            *c = [p.position.x, p.position.y, p.position.z];
        }
        true
    }

    fn moved_from(&self, shown: &[[f64; 3]]) -> bool {
        self.centre.iter().zip(shown).any(|(a, b)| (0..3).any(|k| (a[k] - b[k]).abs() > MOVE_THRESHOLD))
    }
}

/// The node that publishes both topics (session side: it reads the world's `/fruits`).
pub struct SceneView {
    scene: Option<MarkerArray>,
    fruit: FruitSet,
    shown: Option<Vec<[f64; 3]>>,
    seen: u64,
}

impl SceneView {
    pub fn new(gh: &Greenhouse) -> SceneView {
        SceneView { scene: Some(scene_markers(gh, Time::default())), fruit: FruitSet::of(gh), shown: None, seen: 0 }
    }
}

fn restamp(mut m: MarkerArray, stamp: Time) -> MarkerArray {
    for k in &mut m.markers {
        k.header.stamp = stamp;
    }
    m
}

impl Node for SceneView {
    fn name(&self) -> &str {
        "scene_view"
    }

    fn step(&mut self, t_ns: i64, bus: &mut Bus) -> Result<()> {
        let stamp = Time::from_nanos(t_ns);
        if let Some(scene) = self.scene.take() {
            bus.publish(SCENE_MARKERS, t_ns, &restamp(scene, stamp));
        }
        if let Some(poses) = bus.take_new::<PoseArray>(FRUITS, &mut self.seen)? {
            self.fruit.update(&poses);
        }
        let changed = match &self.shown {
            None => true,
            Some(shown) => self.fruit.moved_from(shown),
        };
        if changed {
            bus.publish(FRUIT_MARKERS, t_ns, &self.fruit.markers(stamp));
            self.shown = Some(self.fruit.centre.clone());
        }
        Ok(())
    }
}

/// Static transforms (tf2_msgs/TFMessage, latched).
pub const TF_STATIC: &str = "/tf_static";
/// The wheel odometry (nav_msgs/Odometry, odom -> base_link), as agrisim_nodes::OdomTf reads it.
const ODOM: &str = "/odom";
/// The names ([`Node::name`]) of the nodes that publish map -> odom: agrisim_nav's
/// localization node, and its navigator (which may embed one).
pub const LOCALIZERS: [&str; 2] = ["localization", "navigator"];

/// Whether one of `nodes` localizes the robot (publishes map -> odom).
pub fn localizes(nodes: &[Box<dyn Node>]) -> bool {
    nodes.iter().any(|n| LOCALIZERS.contains(&n.name()))
}

/// map -> odom, fixed at the start, for a run without localization: the transform that puts
/// the odometry's first pose on the robot's start pose (the chassis's x0, y0, yaw0 in the map
/// frame), map -> odom = start * odom_0^-1. agrisim's odometry (the chassis, the odometry
/// adapter) starts at the start pose itself, in map coordinates, so this is the identity
/// there; an odometry that starts at zero (REP 105's usual odom) gets the start pose. With no
/// localizer to correct the drift, map -> odom stays where it started. It joins the markers'
/// `map` frame to the robot's tree, so a viewer that follows base_link draws the greenhouse
/// where the robot sees it. Published once on `/tf_static` (latched), at the step of the
/// first `/odom`, with the static transforms published before it (robot_state_publisher's):
/// the bus keeps one message of a latched topic for a reader that joins later (the Foxglove
/// view), so that message carries the whole static tree. Only for runs without a localizer:
/// a frame with two parents breaks the tree ([`with_map_odom`]).
pub struct StaticMapOdom {
    pose: [f64; 3],
    sent: bool,
    seen: u64,
    odom_seen: u64,
    /// The static transforms seen so far, by child frame (no odom).
    statics: BTreeMap<String, TransformStamped>,
}

impl StaticMapOdom {
    /// `start`: x \[m\], y \[m\], yaw \[rad\] of the base at the start, in the map frame.
    pub fn new(start: [f64; 3]) -> StaticMapOdom {
        StaticMapOdom { pose: start, sent: false, seen: 0, odom_seen: 0, statics: BTreeMap::new() }
    }
}

/// map -> odom (x, y, yaw) that maps the odometry pose `odom` onto the map pose `start`:
/// start * odom^-1, in the plane.
pub fn map_odom(start: [f64; 3], odom: [f64; 3]) -> [f64; 3] {
    let yaw = start[2] - odom[2];
    let (s, c) = yaw.sin_cos();
    [start[0] - (c * odom[0] - s * odom[1]), start[1] - (s * odom[0] + c * odom[1]), yaw]
}

impl Node for StaticMapOdom {
    fn name(&self) -> &str {
        "map_odom"
    }

    fn step(&mut self, t_ns: i64, bus: &mut Bus) -> Result<()> {
        if self.sent {
            return Ok(());
        }
        if let Some(m) = bus.take_new::<TFMessage>(TF_STATIC, &mut self.seen)? {
            for t in m.transforms.into_iter().filter(|t| t.child_frame_id != "odom") {
                self.statics.insert(t.child_frame_id.clone(), t);
            }
        }
        let Some(odom) = bus.take_new::<Odometry>(ODOM, &mut self.odom_seen)? else {
            return Ok(());
        };
        let p = &odom.pose.pose;
        let [x, y, yaw] = map_odom(self.pose, [p.position.x, p.position.y, p.orientation.yaw()]);
        let mut transforms: Vec<TransformStamped> = self.statics.values().cloned().collect();
        transforms.push(TransformStamped {
            header: Header { stamp: Time::from_nanos(t_ns), frame_id: FRAME.into() },
            child_frame_id: "odom".into(),
            transform: Transform { translation: Vector3 { x, y, z: 0.0 }, rotation: Quaternion::from_yaw(yaw) },
        });
        bus.publish(TF_STATIC, t_ns, &TFMessage { transforms });
        self.sent = true;
        self.statics.clear();
        Ok(())
    }
}

/// `nodes` and then a [`StaticMapOdom`] at `start`, unless one of them localizes (or there
/// is no start pose: no mobile base).
pub fn with_map_odom(mut nodes: Vec<Box<dyn Node>>, start: Option<[f64; 3]>) -> Vec<Box<dyn Node>> {
    if let Some(start) = start {
        if !localizes(&nodes) {
            nodes.push(Box::new(StaticMapOdom::new(start)));
        }
    }
    nodes
}

#[cfg(test)]
mod tests {
    use super::*;
    use agrisim_msgs::geometry_msgs::Pose;
    use agrisim_msgs::Message;
    use agrisim_scene::{generate, GreenhouseConfig};
    use std::collections::BTreeSet;

    fn default_greenhouse() -> Greenhouse {
        // The paper's greenhouse, as models/scenarios/default.toml sets it.
        let cfg = GreenhouseConfig::from_toml_str("active_rows = 6\naisle_width = 2.0\n").unwrap();
        generate(&cfg, cfg.seed)
    }

    fn count(gh: &Greenhouse, f: impl Fn(Kind) -> bool) -> usize {
        gh.objects.iter().filter(|o| f(o.kind)).count()
    }

    fn points_in(m: &MarkerArray, ns: &str) -> usize {
        m.markers.iter().filter(|k| k.ns == ns).map(|k| k.points.len()).sum()
    }

    /// Every object is drawn, by the rule of its shape, in one marker per kind and width.
    #[test]
    fn instanced_markers_cover_every_object() {
        let gh = default_greenhouse();
        let m = scene_markers(&gh, Time::default());
        let kinds = |k: Kind| count(&gh, |o| o == k);
        let shaped = |k: Kind, cyl: bool| {
            gh.objects.iter().filter(|o| o.kind == k && matches!(o.shape, Shape::Cylinder { .. }) == cyl).count()
        };
        let pedicels = gh
            .objects
            .iter()
            .filter(|o| {
                o.kind == Kind::Truss && matches!(o.shape, Shape::Cylinder { radius, .. } if radius <= PEDICEL_RADIUS)
            })
            .count();
        // One triangle per compound leaf (each has one rachis), its far edge level.
        assert_eq!(points_in(&m, "leaves"), 3 * shaped(Kind::Leaf, true));
        let leaves = m.markers.iter().find(|k| k.ns == "leaves").unwrap();
        let level = leaves.points.chunks(3).filter(|t| t[1].z == t[2].z && t[1] != t[2]).count();
        assert!(level * 100 >= 99 * leaves.points.len() / 3, "{level} level leaves");
        assert!(shaped(Kind::Leaf, false) > 1000 && pedicels > 1000);
        assert_eq!(points_in(&m, "stems"), 2 * kinds(Kind::Stem));
        assert_eq!(points_in(&m, "posts"), 2 * kinds(Kind::Post));
        assert_eq!(points_in(&m, "pipes"), 2 * kinds(Kind::HeatingPipe));
        assert_eq!(points_in(&m, "trusses"), 2 * (kinds(Kind::Truss) - pedicels));
        assert_eq!(points_in(&m, "walls"), 36 * kinds(Kind::Wall));
        assert_eq!(points_in(&m, "gutters"), 36 * kinds(Kind::Gutter));
        assert_eq!(points_in(&m, "floor"), 36);
        assert!(kinds(Kind::Leaf) > 1000 && kinds(Kind::Stem) > 100, "a real crop");
        // Instanced: a handful of markers for thousands of objects.
        assert!(m.markers.len() <= 16, "{} markers", m.markers.len());
        for k in &m.markers {
            assert_eq!(k.header.frame_id, "map");
            let per = match k.r#type {
                Marker::TRIANGLE_LIST => 3,
                Marker::LINE_LIST => 2,
                Marker::SPHERE_LIST => 1,
                t => panic!("unexpected marker type {t} in {}", k.ns),
            };
            assert!(!k.points.is_empty() && k.points.len() % per == 0, "{} {}", k.ns, k.points.len());
            assert!(k.scale.x > 0.0 && k.color.a > 0.0);
        }
        // Stems are drawn as thick as they are.
        let stems = m.markers.iter().find(|k| k.ns == "stems").unwrap();
        let r = gh.objects.iter().find_map(|o| match (o.kind, o.shape) {
            (Kind::Stem, Shape::Cylinder { radius, .. }) => Some(radius),
            _ => None,
        });
        assert!((stems.scale.x - 2.0 * r.unwrap()).abs() <= 0.0005 + 1e-12);
        // Fruit: one sphere list per stage, coloured by stage, all fruit in them.
        let fruit = FruitSet::of(&gh);
        let fm = fruit.markers(Time::default());
        assert_eq!(points_in(&fm, "fruit"), count(&gh, |k| matches!(k, Kind::Fruit { .. })));
        for k in &fm.markers {
            assert_eq!(k.r#type, Marker::SPHERE_LIST);
            let [r, g, b] = RIPENESS_COLOURS[k.id as usize - 1];
            assert_eq!((k.color.r, k.color.g, k.color.b), (r, g, b));
        }
        let red = fm.markers.iter().find(|k| k.id == 6).expect("ripe fruit in the default crop");
        assert!(red.color.r > 3.0 * red.color.g, "stage 6 is red");
    }

    /// The default greenhouse's markers stay light: the bound is 2 MB.
    #[test]
    fn default_greenhouse_markers_are_under_2_mb() {
        let gh = default_greenhouse();
        let scene = scene_markers(&gh, Time::default()).to_cdr().len();
        let fruit = FruitSet::of(&gh).markers(Time::default()).to_cdr().len();
        eprintln!("default greenhouse: /scene/markers {scene} B, /scene/fruit_markers {fruit} B");
        assert!(scene + fruit < 2_000_000, "{scene} + {fruit} bytes");
        assert!(scene > 100_000, "the crop is in it ({scene} B)");
    }

    #[test]
    fn boxes_are_closed_and_a_leaf_is_one_triangle() {
        let pl = Placement::yawed([1.0, 2.0, 3.0], 0.3);
        let mut tri = Vec::new();
        box_triangles([0.5, 0.25, 0.125], &pl, &mut tri);
        assert_eq!(tri.len(), 36);
        // Every corner of the box is used, nothing outside it.
        for p in &tri {
            let d = [p.x - 1.0, p.y - 2.0, p.z - 3.0];
            let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            assert!((r - (0.25f64 + 0.0625 + 0.015625).sqrt()).abs() < GRID);
        }
        // A leaf along +x from (0, 0, 1): rachis 0.25 m, leaflets reaching 0.375 m out and
        // 0.0625 m to either side (on the grid, so the rounding changes nothing).
        let rachis = Object {
            id: 0,
            name: "leaf".into(),
            kind: Kind::Leaf,
            shape: Shape::Cylinder { radius: 0.0025, half_height: 0.125 },
            placement: Placement::axis_angle([0.125, 0.0, 1.0], [0.0, 1.0, 0.0], std::f64::consts::FRAC_PI_2),
        };
        let mut tri = Vec::new();
        leaf_triangle(&rachis, &[[0.25, 0.0625, 1.0], [0.375, 0.0, 1.0], [0.125, -0.03125, 1.0]], &mut tri);
        let xyz: Vec<[f64; 3]> = tri.iter().map(|p| [p.x, p.y, p.z]).collect();
        assert_eq!(xyz, [[0.0, 0.0, 1.0], [0.375, -0.0625, 1.0], [0.375, 0.0625, 1.0]]);
        assert_eq!(point([0.1234, -7.0001, 1.0]).x, 16.0 / 128.0);
        assert_eq!(point([0.1234, -7.0001, 1.0]).y, -7.0);
    }

    /// Both topics go out at the first instant; fruit markers again only when a fruit moves.
    #[test]
    fn published_once_and_again_when_fruit_move() {
        let gh = default_greenhouse();
        let mut node = SceneView::new(&gh);
        let mut bus = Bus::default();
        let (mut s, mut f) = (0, 0);
        let mut fruit = FruitSet::of(&gh);
        let poses = |c: &[[f64; 3]]| PoseArray {
            header: Header::default(),
            poses: c.iter().map(|p| Pose { position: point(*p), ..Default::default() }).collect(),
        };
        bus.publish(FRUITS, 0, &poses(&fruit.centre));
        node.step(0, &mut bus).unwrap();
        assert!(bus.take_new::<MarkerArray>(SCENE_MARKERS, &mut s).unwrap().is_some());
        assert!(bus.take_new::<MarkerArray>(FRUIT_MARKERS, &mut f).unwrap().is_some());
        // The same poses again, and a jitter under the threshold: nothing new.
        fruit.centre[3][2] += 0.5 * MOVE_THRESHOLD;
        bus.publish(FRUITS, 100, &poses(&fruit.centre));
        node.step(100, &mut bus).unwrap();
        assert!(bus.take_new::<MarkerArray>(SCENE_MARKERS, &mut s).unwrap().is_none());
        assert!(bus.take_new::<MarkerArray>(FRUIT_MARKERS, &mut f).unwrap().is_none());
        // Fruit 3 is picked and lifted 10 cm: re-sent with the fruit where it is.
        fruit.centre[3][2] += 0.1;
        bus.publish(FRUITS, 200, &poses(&fruit.centre));
        node.step(200, &mut bus).unwrap();
        assert!(bus.take_new::<MarkerArray>(SCENE_MARKERS, &mut s).unwrap().is_none());
        let m = bus.take_new::<MarkerArray>(FRUIT_MARKERS, &mut f).unwrap().expect("fruit moved");
        let z = fruit.centre[3][2];
        assert!(m.markers.iter().flat_map(|k| &k.points).any(|p| (p.z - z).abs() <= 0.5 * GRID));
        assert_eq!(m.markers[0].header.stamp, Time::from_nanos(200));
    }

    /// Every transform published on /tf and /tf_static by `nodes` stepping at 0 and 0.1 s,
    /// with the wheel odometry's pose (x, y, yaw) at those times on /odom.
    fn transforms_with(
        mut nodes: Vec<Box<dyn Node>>,
        odom_poses: [[f64; 3]; 2],
    ) -> (Vec<(String, TransformStamped)>, Vec<String>) {
        let mut bus = Bus::default();
        let mut tap = agrisim_bus::Tap::default();
        let mut out = Vec::new();
        for (t, [x, y, yaw]) in [0, 100_000_000].into_iter().zip(odom_poses) {
            let mut odom = Odometry { child_frame_id: "base_link".into(), ..Default::default() };
            odom.header = Header { stamp: Time::from_nanos(t), frame_id: "odom".into() };
            odom.pose.pose.position.x = x;
            odom.pose.pose.position.y = y;
            odom.pose.pose.orientation = Quaternion::from_yaw(yaw);
            bus.publish(ODOM, t, &odom);
            for n in &mut nodes {
                n.step(t, &mut bus).unwrap();
            }
            for (topic, _, sample) in tap.take(&mut bus, |t| t == "/tf" || t == TF_STATIC) {
                out.extend(
                    TFMessage::from_cdr(&sample.cdr).unwrap().transforms.into_iter().map(|x| (topic.clone(), x)),
                );
            }
        }
        (out, nodes.iter().map(|n| n.name().to_string()).collect())
    }

    /// [`transforms_with`] an odometry that starts at zero and moves 0.3 m forward, turning 0.2 rad.
    fn transforms(nodes: Vec<Box<dyn Node>>) -> (Vec<(String, TransformStamped)>, Vec<String>) {
        transforms_with(nodes, [[0.0; 3], [0.3, 0.0, 0.2]])
    }

    /// map -> base_link (x, y, yaw) through the last transform of each frame, and its root.
    fn map_base(tf: &[(String, TransformStamped)]) -> ([f64; 3], String) {
        let parent: BTreeMap<&str, &TransformStamped> =
            tf.iter().map(|(_, t)| (t.child_frame_id.as_str(), t)).collect();
        let (mut frame, mut pose) = ("base_link", [0.0, 0.0, 0.0]);
        while let Some(t) = parent.get(frame) {
            let (tr, yaw) = (&t.transform.translation, t.transform.rotation.yaw());
            let (c, s) = (yaw.cos(), yaw.sin());
            pose = [tr.x + c * pose[0] - s * pose[1], tr.y + s * pose[0] + c * pose[1], yaw + pose[2]];
            frame = t.header.frame_id.as_str();
        }
        (pose, frame.to_string())
    }

    /// A plain run (robot_state_publisher, odom -> base_link from /odom, no localizer): map ->
    /// odom on /tf_static joins map to base_link, and the chain places base_link at the start
    /// pose moved by the odometry since the start, whether the odometry starts at zero (REP
    /// 105's usual odom) or at the start pose in map coordinates (agrisim's chassis and odometry
    /// adapter: map -> odom is then the identity, not the start pose again).
    #[test]
    fn without_a_localizer_map_odom_puts_base_link_at_the_start_pose_moved_by_odometry() {
        let start = [1.0, 2.0, 0.5];
        let want = [1.0 + 0.3 * 0.5f64.cos(), 2.0 + 0.3 * 0.5f64.sin(), 0.7];
        let nodes = || -> Vec<Box<dyn Node>> {
            vec![Box::new(agrisim_nodes::RobotStatePublisher::agrisim()), Box::new(agrisim_nodes::OdomTf::default())]
        };
        for (odom, map_odom_want) in [([[0.0; 3], [0.3, 0.0, 0.2]], start), ([start, want], [0.0; 3])] {
            let (tf, _) = transforms_with(with_map_odom(nodes(), Some(start)), odom);
            let map_odom: Vec<_> = tf.iter().filter(|(_, t)| t.child_frame_id == "odom").collect();
            assert_eq!(map_odom.len(), 1, "map -> odom once: {map_odom:?}");
            assert_eq!((map_odom[0].0.as_str(), map_odom[0].1.header.frame_id.as_str()), (TF_STATIC, "map"));
            let (tr, q) = (&map_odom[0].1.transform.translation, &map_odom[0].1.transform.rotation);
            let got = [tr.x, tr.y, q.yaw()];
            assert!(
                (0..3).all(|k| (got[k] - map_odom_want[k]).abs() < 1e-9),
                "map -> odom {got:?}, want {map_odom_want:?}"
            );
            // The one /tf_static message a late reader gets holds robot_state_publisher's too.
            let last_static: BTreeSet<&str> = tf
                .iter()
                .filter(|(topic, t)| topic == TF_STATIC && t.header.frame_id == map_odom[0].1.header.frame_id)
                .map(|(_, t)| t.child_frame_id.as_str())
                .collect();
            assert!(last_static.contains("odom"));
            assert!(
                tf.iter().any(|(topic, t)| topic == TF_STATIC && t.child_frame_id != "odom"),
                "no static robot transforms"
            );
            let (pose, root) = map_base(&tf);
            assert_eq!(root, "map", "base_link's root");
            assert!((0..3).all(|k| (pose[k] - want[k]).abs() < 1e-9), "map -> base_link {pose:?}, want {want:?}");
        }
        // map_odom itself: start * odom^-1 puts the odometry's pose on the start.
        let m = map_odom([3.0, -1.0, 1.2], [0.5, 0.25, -0.4]);
        let (c, s) = (m[2].cos(), m[2].sin());
        let back = [m[0] + c * 0.5 - s * 0.25, m[1] + s * 0.5 + c * 0.25, m[2] - 0.4];
        assert!((0..3).all(|k| (back[k] - [3.0, -1.0, 1.2][k]).abs() < 1e-12), "{back:?}");
    }

    /// A node that publishes map -> odom on /tf as agrisim_nav's localizer does.
    struct FakeLocalizer;

    impl Node for FakeLocalizer {
        fn name(&self) -> &str {
            "localization"
        }

        fn step(&mut self, t_ns: i64, bus: &mut Bus) -> Result<()> {
            let tf = TransformStamped {
                header: Header { stamp: Time::from_nanos(t_ns), frame_id: FRAME.into() },
                child_frame_id: "odom".into(),
                ..Default::default()
            };
            bus.publish("/tf", t_ns, &TFMessage { transforms: vec![tf] });
            Ok(())
        }
    }

    /// With a localizer, map -> odom has one publisher: the localizer (two parents of odom
    /// would break the tree). The localizer's and the navigator's names are those of agrisim_nav.
    #[test]
    fn with_a_localizer_map_odom_has_one_publisher() {
        let cfg = agrisim_nav::NavConfig::default();
        assert!(LOCALIZERS.contains(&agrisim_nav::Localizer::new(&cfg).name()));
        assert!(LOCALIZERS.contains(&agrisim_nav::Navigator::new(cfg).name()));
        let nodes: Vec<Box<dyn Node>> = vec![Box::new(agrisim_nodes::OdomTf::default()), Box::new(FakeLocalizer)];
        let (tf, names) = transforms(with_map_odom(nodes, Some([1.0, 2.0, 0.5])));
        assert_eq!(names, ["odom_tf", "localization"]);
        let sources: BTreeSet<&str> =
            tf.iter().filter(|(_, t)| t.child_frame_id == "odom").map(|(topic, _)| topic.as_str()).collect();
        assert_eq!(sources, BTreeSet::from(["/tf"]));
        // No start pose (no mobile base): nothing added either.
        let (_, names) = transforms(with_map_odom(vec![Box::new(agrisim_nodes::OdomTf::default())], None));
        assert_eq!(names, ["odom_tf"]);
    }
}
