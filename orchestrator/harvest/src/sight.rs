//! Harvest by sight: the task names a region of the row, not a fruit. The node looks for
//! ripe fruit there in the perception node's fruit map (`vision_msgs/Detection3DArray` on
//! `/perception/fruit_map`), plans in the collision scene the mapping node builds from depth
//! (`/mapping/planning_scene`), and asks the mapper to leave its target out of that scene
//! (`/harvest/allowed`), as MoveIt allows the object being grasped. Nothing here reads the
//! world's ground truth.

use agrisim_msgs::agrisim::{CollisionObject, PlanningScene};
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::geometry_msgs::{Point, Pose, Quaternion, Vector3};
use agrisim_msgs::shape_msgs::SolidPrimitive;
use agrisim_msgs::std_msgs::Header;
use agrisim_msgs::vision_msgs::{BoundingBox3D, Detection3D, Detection3DArray};

use crate::geometry::NEIGHBOUR_GAP;

pub mod topics {
    /// The perception node's fruit map (map frame).
    pub const FRUIT_MAP: &str = "/perception/fruit_map";
    /// The mapping node's sensed planning scene (map frame).
    pub const SENSED_SCENE: &str = "/mapping/planning_scene";
    /// The fruit the node is about to grasp, for the mapper to leave out (map frame).
    pub const ALLOWED: &str = "/harvest/allowed";
}

/// Classes the perception node gives ripe fruit (USDA stages 5 and 6).
pub const RIPE_CLASSES: [&str; 2] = ["light_red", "red"];
/// Share of a track's ripeness votes that must be ripe classes.
pub const RIPE_SHARE: f64 = 0.5;
/// Lift positions the scan stops at [m]: the row-facing lift camera (42 deg vertical field of
/// view, about 0.7 m of plant at the row's distance) covers the harvestable heights
/// (0.55-1.75 m) in three stops.
pub const SCAN_LIFTS: [f64; 3] = [0.0, 0.4, 0.8];
/// Time at each scan stop once base and lift are in place [s]: four frames at 5 Hz.
pub const SCAN_DWELL: f64 = 0.8;
/// The allowed sphere is the fruit's perceived radius grown by this [m]: the fit's error and
/// the voxels (1 cm) its surface lies in.
pub const ALLOWED_MARGIN: f64 = 0.02;
/// Scene object id of the perceived target added to the sensed scene.
pub const TARGET_OBJECT: &str = "perceived_target";
/// Sensed space this close to the target's surface is what the fingers push aside on the
/// way in (leaflets, the calyx, the truss and neighbouring fruit), as the planner treats
/// leaves, trusses and touching fruit in the ground-truth scene [m]: about the Franka Hand's
/// finger length.
pub const HAND_ZONE: f64 = 0.05;
/// Sensed boxes longer than this [m] stay obstacles even near the target: long runs are
/// stems, wires and structure, not foliage.
pub const PUSHABLE_SIZE: f64 = 0.06;
/// Scene kind of sensed boxes the hand may push aside (see [`HAND_ZONE`]).
pub const PUSHED_KIND: &str = "pushed";

/// A box of the map frame: where the task's fruit may be.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Region {
    pub x: [f64; 2],
    pub y: [f64; 2],
    pub z: [f64; 2],
}

impl Region {
    pub fn contains(&self, p: [f64; 3]) -> bool {
        [self.x, self.y, self.z].iter().zip(p).all(|(r, v)| r[0] <= v && v <= r[1])
    }

    /// Whether `p` lies at least `margin[axis]` inside both faces of each axis (a negative
    /// margin: at most that far outside).
    pub fn holds(&self, p: [f64; 3], margin: [f64; 3]) -> bool {
        [self.x, self.y, self.z].iter().zip(p).zip(margin).all(|((r, v), m)| r[0] + m <= v && v <= r[1] - m)
    }

    pub fn centre(&self) -> [f64; 3] {
        [self.x, self.y, self.z].map(|r| 0.5 * (r[0] + r[1]))
    }
}

/// A fruit of the perception node's map.
#[derive(Debug, Clone, PartialEq)]
pub struct Seen {
    /// The track id (stable across frames).
    pub id: String,
    pub center: [f64; 3],
    pub radius: f64,
    /// Share of the track's ripeness votes in [`RIPE_CLASSES`].
    pub ripe: f64,
}

/// The fruit of a fruit map in `frame` (others are skipped: the node plans in the map frame).
pub fn fruit_of(map: &Detection3DArray, frame: &str) -> Vec<Seen> {
    if map.header.frame_id.trim_start_matches('/') != frame {
        return vec![];
    }
    map.detections
        .iter()
        .filter_map(|d| {
            let p = &d.bbox.center.position;
            let size = [d.bbox.size.x, d.bbox.size.y, d.bbox.size.z];
            let radius = 0.5 * size.iter().cloned().fold(0.0, f64::max);
            let ripe = d
                .results
                .iter()
                .filter(|h| RIPE_CLASSES.contains(&h.hypothesis.class_id.as_str()))
                .map(|h| h.hypothesis.score)
                .sum();
            let center = [p.x, p.y, p.z];
            (center.iter().all(|v| v.is_finite()) && radius > 0.0).then(|| Seen {
                id: d.id.clone(),
                center,
                radius,
                ripe,
            })
        })
        .collect()
}

/// A fruit of the map this close to a place the node has already tried (picked there, or
/// failed on) is taken for that fruit and not chosen again [m]: about a fruit's radius, so
/// the next fruit of a truss (its centre a diameter away) is still chosen.
pub const TRIED_RADIUS: f64 = 0.025;
/// The perception's centre error to allow for at a region's faces [m] (p95 about 12 mm in
/// the harvest by sight).
pub const REGION_MARGIN: f64 = 0.015;
/// A single task's margins ([`Region::holds`], per axis): a fruit is chosen only when its
/// estimated centre lies [`REGION_MARGIN`] inside every face, as one outside the task's
/// region fails the task.
pub const TASK_MARGIN: [f64; 3] = [REGION_MARGIN; 3];
/// A row's margins: along the row (x) and in height (z) a fruit is chosen when its estimate
/// lies up to [`REGION_MARGIN`] outside. A row's regions abut along x, so an inward margin
/// there left every fruit within it of a boundary to neither region (row by sight, seed 1,
/// code of f2e38eb: 5 of the 23 ripe fruit never chosen lay within 15 mm of a region's
/// face); a fruit just beyond the segment costs one pick and is still a ripe fruit in the
/// box. Across the row (y) the margin stays inward: beyond the plant line hang the fruit of
/// the row's far side, behind its stems.
pub const ROW_MARGIN: [f64; 3] = [-REGION_MARGIN, REGION_MARGIN, -REGION_MARGIN];

/// Fruit one task may decline for want of a collision-free pre-grasp before its planning
/// failure stands (the node then takes the next ripe fruit of the region).
pub const MAX_DECLINED: usize = 2;

/// The largest perceived fruit radius the node picks [m]: the Franka Hand opens 80 mm
/// between its pads ([`crate::geometry::OPEN_WIDTH`]), and the fingers must pass the fruit's
/// equator with a little room on each side. In family draws with large fruit (seed 7001,
/// trial 2: a 43.8 mm fruit, perceived 41.4 mm, 2.7 mm off) every grasp closed on nothing.
pub const GRASPABLE_RADIUS: f64 = 0.5 * crate::geometry::OPEN_WIDTH - 0.002;

/// The fruit to pick: ripe, no larger than [`GRASPABLE_RADIUS`], held by `region` with
/// `margin` ([`Region::holds`]), not within [`TRIED_RADIUS`] of a place in `tried`; of those
/// the one nearest the aisle line `aisle_y` (least plant in front of it), then nearest the
/// region's centre along the row.
pub fn choose(seen: &[Seen], region: &Region, margin: [f64; 3], aisle_y: f64, tried: &[[f64; 3]]) -> Option<Seen> {
    let cx = region.centre()[0];
    ripe_untried(seen, region, margin, tried)
        .filter(|s| s.radius <= GRASPABLE_RADIUS)
        .min_by(|a, b| {
            let key = |s: &Seen| ((s.center[1] - aisle_y).abs(), (s.center[0] - cx).abs());
            let (ka, kb) = (key(a), key(b));
            ka.0.total_cmp(&kb.0).then(ka.1.total_cmp(&kb.1)).then(a.id.cmp(&b.id))
        })
        .cloned()
}

/// The ripe fruit of `region` that [`choose`] passed over only for being wider than the hand
/// opens ([`GRASPABLE_RADIUS`]): their perceived radii [m], largest first. Non-empty when a
/// task ends with nothing to pick: the region's ripe fruit were seen, and too wide.
pub fn too_wide(seen: &[Seen], region: &Region, margin: [f64; 3], tried: &[[f64; 3]]) -> Vec<f64> {
    let mut r: Vec<f64> =
        ripe_untried(seen, region, margin, tried).filter(|s| s.radius > GRASPABLE_RADIUS).map(|s| s.radius).collect();
    r.sort_by(|a, b| b.total_cmp(a));
    r
}

/// The ripe fruit `region` holds with `margin`, not within [`TRIED_RADIUS`] of a place in
/// `tried`: what [`choose`] and [`too_wide`] sort by size.
fn ripe_untried<'a>(
    seen: &'a [Seen],
    region: &'a Region,
    margin: [f64; 3],
    tried: &'a [[f64; 3]],
) -> impl Iterator<Item = &'a Seen> {
    seen.iter()
        .filter(move |s| s.ripe > RIPE_SHARE && region.holds(s.center, margin))
        .filter(|s| tried.iter().all(|p| dist(*p, s.center) > TRIED_RADIUS))
}

/// The chosen fruit in a new fruit map: its track `id`, else (the perception node merged that
/// track into another: two tracks closer than a radius are one fruit) the track nearest the
/// last estimate `at` of radius `r`, if its centre lies within the larger radius of it.
pub fn follow<'a>(map: &'a [Seen], id: &str, at: [f64; 3], r: f64) -> Option<&'a Seen> {
    map.iter().find(|f| f.id == id).or_else(|| {
        map.iter()
            .filter(|f| dist(f.center, at) < f.radius.max(r))
            .min_by(|a, b| dist(a.center, at).total_cmp(&dist(b.center, at)).then(a.id.cmp(&b.id)))
    })
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt()
}

/// `/harvest/allowed`: the target as a sphere (its box's half size the radius, grown by
/// [`ALLOWED_MARGIN`]); none: an empty array.
pub fn allowed(stamp: Time, target: Option<([f64; 3], f64)>) -> Detection3DArray {
    let header = Header { stamp, frame_id: "map".into() };
    let detections = target
        .map(|(c, r)| {
            let side = 2.0 * (r + ALLOWED_MARGIN);
            Detection3D {
                header: header.clone(),
                results: vec![],
                bbox: BoundingBox3D {
                    center: Pose { position: Point { x: c[0], y: c[1], z: c[2] }, orientation: Quaternion::IDENTITY },
                    size: Vector3 { x: side, y: side, z: side },
                },
                id: TARGET_OBJECT.into(),
            }
        })
        .into_iter()
        .collect();
    Detection3DArray { header, detections }
}

/// Scene id prefix of the perceived fruit [`with_target`] puts in place of their voxels.
pub const PERCEIVED_PREFIX: &str = "perceived/";

/// The sensed scene with the perceived target in it as a fruit sphere, so the planner treats
/// it as in the ground-truth scene (the hand may touch it, and it goes with the hand once
/// held).
///
/// The other perceived fruit of `seen` (any ripeness) are shape-filtered, as MoveIt's
/// occupancy map monitor filters known objects out of the depth and adds their shapes: each
/// small sensed box lying wholly within a fruit's sphere grown by [`ALLOWED_MARGIN`] is
/// dropped, and the fruit goes in as a sphere of kind `fruit` (id [`PERCEIVED_PREFIX`] +
/// track id), so the planner's rules for fruit (touching the target, in a roll's sweep) hold
/// by sight as in the ground-truth scene. A fruit whose sphere holds no sensed box is left
/// out: the depth shows nothing there (a stale track, or a fruit seen only in colour). The
/// voxels of a fruit's surface, each up to 1 cm and padded by the planner, stood up to 1.7 cm
/// proud of it: by-sight trials 16 and 26 (seed 1) found no collision-free wrist pose past a
/// truss of fruit 5-11 cm in front of the target, which the ground-truth scene let pass.
///
/// Small sensed boxes become [`PUSHED_KIND`] where the fingers push them aside:
/// - within [`HAND_ZONE`] of the target's surface;
/// - on a perceived fruit of `seen` (any ripeness) touching the target (surfaces within
///   [`NEIGHBOUR_GAP`]), within [`ALLOWED_MARGIN`] of its surface. The ground-truth scene
///   treats such fruit so; by sight their surface voxels, 5-9 cm in front of the target,
///   blocked the wrist at every roll and approach (by-sight trial 19, seed 1: a turning
///   fruit touching the target from the aisle side).
pub fn with_target(scene: &PlanningScene, c: [f64; 3], r: f64, seen: &[Seen]) -> PlanningScene {
    // The fruit map's other fruit (the target's own track lies within half a radius).
    let others: Vec<&Seen> = seen.iter().filter(|n| dist(n.center, c) > 0.5 * r).collect();
    let touching: Vec<&Seen> =
        others.iter().copied().filter(|n| dist(n.center, c) < r + n.radius + NEIGHBOUR_GAP).collect();
    let mut explains = vec![false; others.len()];
    let mut s = scene.clone();
    s.objects.retain(|o| {
        let Some(far) = small_box_farthest(o) else { return true };
        match others.iter().position(|n| far(n.center) <= n.radius + ALLOWED_MARGIN) {
            Some(k) => {
                explains[k] = true;
                false
            }
            None => true,
        }
    });
    for o in &mut s.objects {
        let Some(near) = small_box_distance(o) else { continue };
        if near(c) <= r + HAND_ZONE || touching.iter().any(|n| near(n.center) <= n.radius + ALLOWED_MARGIN) {
            o.kind = PUSHED_KIND.into();
        }
    }
    for (n, _) in others.iter().zip(&explains).filter(|(_, e)| **e) {
        s.objects.push(fruit_sphere(format!("{PERCEIVED_PREFIX}{}", n.id), n.center, n.radius));
    }
    s.objects.push(fruit_sphere(TARGET_OBJECT.into(), c, r));
    s
}

/// A scene object of kind `fruit`: a sphere.
fn fruit_sphere(id: String, c: [f64; 3], r: f64) -> CollisionObject {
    CollisionObject {
        id,
        kind: "fruit".into(),
        primitive: SolidPrimitive { r#type: SolidPrimitive::SPHERE, dimensions: vec![r], ..Default::default() },
        pose: Pose { position: Point { x: c[0], y: c[1], z: c[2] }, orientation: Quaternion::IDENTITY },
    }
}

/// The distance from a point to a sensed box (axis-aligned: the nearest point is a clamp),
/// for boxes no longer than [`PUSHABLE_SIZE`]; None for other objects.
fn small_box_distance(o: &CollisionObject) -> Option<impl Fn([f64; 3]) -> f64> {
    let (m, half) = small_box(o)?;
    Some(move |q: [f64; 3]| {
        (0..3).map(|i| (q[i].clamp(m[i] - half[i], m[i] + half[i]) - q[i]).powi(2)).sum::<f64>().sqrt()
    })
}

/// The distance from a point to a sensed box's farthest corner, for boxes no longer than
/// [`PUSHABLE_SIZE`]; None for other objects.
fn small_box_farthest(o: &CollisionObject) -> Option<impl Fn([f64; 3]) -> f64> {
    let (m, half) = small_box(o)?;
    Some(move |q: [f64; 3]| (0..3).map(|i| ((q[i] - m[i]).abs() + half[i]).powi(2)).sum::<f64>().sqrt())
}

/// Centre and half sides of an axis-aligned sensed box no longer than [`PUSHABLE_SIZE`].
fn small_box(o: &CollisionObject) -> Option<([f64; 3], [f64; 3])> {
    let d = &o.primitive.dimensions;
    if o.primitive.r#type != SolidPrimitive::BOX || d.len() < 3 || d.iter().any(|&v| v > PUSHABLE_SIZE) {
        return None;
    }
    let p = &o.pose.position;
    Some(([p.x, p.y, p.z], [0.5 * d[0], 0.5 * d[1], 0.5 * d[2]]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use agrisim_msgs::vision_msgs::{ObjectHypothesis, ObjectHypothesisWithPose};

    fn track(id: &str, c: [f64; 3], r: f64, votes: &[(&str, f64)]) -> Detection3D {
        Detection3D {
            header: Header::default(),
            results: votes
                .iter()
                .map(|(k, s)| ObjectHypothesisWithPose {
                    hypothesis: ObjectHypothesis { class_id: k.to_string(), score: *s },
                    ..Default::default()
                })
                .collect(),
            bbox: BoundingBox3D {
                center: Pose { position: Point { x: c[0], y: c[1], z: c[2] }, orientation: Quaternion::IDENTITY },
                size: Vector3 { x: 2.0 * r, y: 2.0 * r, z: 2.0 * r },
            },
            id: id.into(),
        }
    }

    #[test]
    fn the_nearest_ripe_fruit_in_the_region_is_chosen() {
        let region = Region { x: [1.0, 2.0], y: [0.2, 1.0], z: [0.5, 1.8] };
        let map = Detection3DArray {
            header: Header { frame_id: "map".into(), ..Default::default() },
            detections: vec![
                // ripe, in the region, deep in the row
                track("1", [1.5, 0.7, 1.0], 0.03, &[("red", 0.9), ("pink", 0.1)]),
                // ripe, in the region, nearest the aisle (y = 0): the one
                track("2", [1.8, 0.4, 1.2], 0.03, &[("light_red", 0.6), ("turning", 0.4)]),
                // nearer still but green
                track("3", [1.5, 0.3, 1.0], 0.03, &[("green", 1.0)]),
                // ripe and nearer, but outside the region along the row
                track("4", [2.3, 0.3, 1.0], 0.03, &[("red", 1.0)]),
                // half ripe votes: not ripe enough
                track("5", [1.2, 0.35, 1.0], 0.03, &[("red", 0.5), ("pink", 0.5)]),
            ],
        };
        let seen = fruit_of(&map, "map");
        assert_eq!(seen.len(), 5);
        assert!((seen[1].radius - 0.03).abs() < 1e-12 && (seen[1].ripe - 0.6).abs() < 1e-12);
        assert_eq!(choose(&seen, &region, TASK_MARGIN, 0.0, &[]).map(|s| s.id), Some("2".into()));
        // Tried there already (picked, or failed on): the next one, 1 being within
        // TRIED_RADIUS of its try only when that try was at it.
        assert_eq!(choose(&seen, &region, TASK_MARGIN, 0.0, &[[1.81, 0.41, 1.2]]).map(|s| s.id), Some("1".into()));
        assert_eq!(choose(&seen, &region, TASK_MARGIN, 0.0, &[[1.81, 0.41, 1.2], [1.5, 0.7, 1.02]]), None);
        assert_eq!(
            choose(&seen, &region, TASK_MARGIN, 0.0, &[[1.8, 0.4, 1.2 + 1.5 * TRIED_RADIUS]]).map(|s| s.id),
            Some("2".into())
        );
        // Ripe and nearest the aisle, but within REGION_MARGIN of the region's end: its true
        // centre may lie outside the task's stretch.
        let edge = track("6", [2.0 - 0.5 * REGION_MARGIN, 0.25, 1.0], 0.03, &[("red", 1.0)]);
        let with_edge: Vec<Seen> = seen
            .iter()
            .cloned()
            .chain(fruit_of(&Detection3DArray { detections: vec![edge], ..map.clone() }, "map"))
            .collect();
        assert_eq!(choose(&with_edge, &region, TASK_MARGIN, 0.0, &[]).map(|s| s.id), Some("2".into()));
        // A row's stretches abut along x: there it is chosen, and so is one just beyond the
        // end, or just below the lowest height; one just beyond the plant line (y) is not.
        assert_eq!(choose(&with_edge, &region, ROW_MARGIN, 0.0, &[]).map(|s| s.id), Some("6".into()));
        for (c, chosen) in [
            ([2.0 + 0.5 * REGION_MARGIN, 0.25, 1.0], true),
            ([2.0 + 1.5 * REGION_MARGIN, 0.25, 1.0], false),
            ([1.5, 0.25, 0.5 - 0.5 * REGION_MARGIN], true),
            ([1.5, 1.0 + 0.5 * REGION_MARGIN, 1.0], false),
            ([1.5, 1.0 - 0.5 * REGION_MARGIN, 1.0], false),
        ] {
            let one = fruit_of(
                &Detection3DArray { detections: vec![track("8", c, 0.03, &[("red", 1.0)])], ..map.clone() },
                "map",
            );
            assert_eq!(choose(&one, &region, ROW_MARGIN, 0.0, &[]).is_some(), chosen, "{c:?}");
        }
        // Ripe and nearest the aisle, but too large for the hand.
        let large = track("7", [1.5, 0.25, 1.0], GRASPABLE_RADIUS + 0.001, &[("red", 1.0)]);
        let with_large: Vec<Seen> = seen
            .iter()
            .cloned()
            .chain(fruit_of(&Detection3DArray { detections: vec![large], ..map.clone() }, "map"))
            .collect();
        assert_eq!(choose(&with_large, &region, TASK_MARGIN, 0.0, &[]).map(|s| s.id), Some("2".into()));
        // Only it left (the others tried): nothing to choose, and it is named as too wide.
        let all_tried = [[1.8, 0.4, 1.2], [1.5, 0.7, 1.0]];
        assert_eq!(choose(&with_large, &region, TASK_MARGIN, 0.0, &all_tried), None);
        assert_eq!(too_wide(&with_large, &region, TASK_MARGIN, &all_tried), vec![GRASPABLE_RADIUS + 0.001]);
        assert!(too_wide(&seen, &region, TASK_MARGIN, &all_tried).is_empty());
        assert!(too_wide(&with_large, &region, TASK_MARGIN, &[[1.5, 0.25, 1.0]]).is_empty());
        // Another frame than the map's is not read.
        let odom = Detection3DArray { header: Header { frame_id: "odom".into(), ..Default::default() }, ..map };
        assert!(fruit_of(&odom, "map").is_empty());
        assert_eq!(choose(&[], &region, TASK_MARGIN, 0.0, &[]), None);
    }

    #[test]
    fn the_chosen_fruit_is_followed_into_the_track_it_was_merged_with() {
        let f = |id: &str, c: [f64; 3], r: f64| Seen { id: id.into(), center: c, radius: r, ripe: 1.0 };
        let map = [f("7", [1.0, 0.0, 1.0], 0.03), f("80", [0.0, 0.03, 1.0], 0.04), f("81", [0.0, -0.07, 1.0], 0.03)];
        // Still there: itself, wherever it is now.
        assert_eq!(follow(&map, "7", [0.0, 0.0, 1.0], 0.04).map(|s| &s.id[..]), Some("7"));
        // Gone (merged): the track within the larger radius of where it was.
        assert_eq!(follow(&map, "55", [0.0, 0.0, 1.0], 0.04).map(|s| &s.id[..]), Some("80"));
        // Gone, and nothing overlaps where it was: none.
        assert_eq!(follow(&map, "55", [0.0, 0.2, 1.0], 0.04), None);
    }

    #[test]
    fn the_target_is_allowed_and_added_to_the_scene() {
        let a = allowed(Time::from_nanos(5), Some(([1.0, 2.0, 3.0], 0.03)));
        assert_eq!(a.detections.len(), 1);
        assert!((a.detections[0].bbox.size.x - 2.0 * (0.03 + ALLOWED_MARGIN)).abs() < 1e-12);
        assert!(allowed(Time::from_nanos(5), None).detections.is_empty());
        let s = with_target(&PlanningScene::default(), [1.0, 2.0, 3.0], 0.03, &[]);
        assert_eq!((s.objects.len(), s.objects[0].kind.as_str()), (1, "fruit"));
        assert_eq!(s.objects[0].primitive.dimensions, vec![0.03]);
        // A leaflet-sized box 6 cm from the centre is pushed aside; one 10 cm away, and a
        // long one (a stem's run) as near, stay obstacles.
        let slab = |x: f64, size: f64| CollisionObject {
            id: format!("occupied/{x}"),
            kind: "occupied".into(),
            primitive: SolidPrimitive {
                r#type: SolidPrimitive::BOX,
                dimensions: vec![size, 0.02, 0.01],
                ..Default::default()
            },
            pose: Pose { position: Point { x: 1.0 + x, y: 2.0, z: 3.0 }, orientation: Quaternion::IDENTITY },
        };
        let sensed =
            PlanningScene { objects: vec![slab(0.07, 0.02), slab(0.11, 0.02), slab(0.1, 0.12)], ..Default::default() };
        let kinds: Vec<String> =
            with_target(&sensed, [1.0, 2.0, 3.0], 0.03, &[]).objects.iter().map(|o| o.kind.clone()).collect();
        assert_eq!(kinds, ["pushed", "occupied", "occupied", "fruit"]);
    }

    #[test]
    fn the_surface_of_a_perceived_fruit_touching_the_target_is_pushed_aside() {
        let (c, r) = ([1.0, 2.0, 3.0], 0.03);
        let voxel = |y: f64| CollisionObject {
            id: format!("occupied/{y}"),
            kind: "occupied".into(),
            primitive: SolidPrimitive { r#type: SolidPrimitive::BOX, dimensions: vec![0.01; 3], ..Default::default() },
            pose: Pose { position: Point { x: 1.0, y, z: 3.0 }, orientation: Quaternion::IDENTITY },
        };
        let fruit = |id: &str, y: f64| Seen { id: id.into(), center: [1.0, y, 3.0], radius: 0.03, ripe: 0.0 };
        // A green fruit touching the target on the aisle side (centres 6 cm apart), a voxel
        // 4 cm from its centre on the aisle side, 10.5 cm from the target's (beyond HAND_ZONE
        // of its surface, and not wholly within the fruit's shape-filter shell); another fruit
        // 12 cm away, not touching, with a voxel as far beyond it.
        let sensed = PlanningScene { objects: vec![voxel(1.895), voxel(2.17)], ..Default::default() };
        let kinds = |seen: &[Seen]| -> Vec<String> {
            with_target(&sensed, c, r, seen).objects.iter().map(|o| o.kind.clone()).collect()
        };
        assert_eq!(kinds(&[]), ["occupied", "occupied", "fruit"]);
        let target = fruit("t", 2.0);
        let (near, far) = (fruit("n", 1.94), fruit("f", 2.12));
        assert_eq!(kinds(&[target.clone(), near.clone(), far.clone()]), ["pushed", "occupied", "fruit"]);
        // The target's own track is not a neighbour of itself.
        assert_eq!(kinds(&[target]), ["occupied", "occupied", "fruit"]);
        // Touching is surface to surface within NEIGHBOUR_GAP: 1 mm more and it is not.
        let apart = fruit("a", 2.0 - (2.0 * r + NEIGHBOUR_GAP + 0.001));
        let sensed = PlanningScene { objects: vec![voxel(apart.center[1] - 0.045)], ..Default::default() };
        let kinds: Vec<String> = with_target(&sensed, c, r, &[apart]).objects.iter().map(|o| o.kind.clone()).collect();
        assert_eq!(kinds, ["occupied", "fruit"]);
    }

    #[test]
    fn perceived_fruit_replace_the_voxels_of_their_surface() {
        let (c, r) = ([1.0, 2.0, 3.0], 0.03);
        let cube = |id: &str, p: [f64; 3], size: [f64; 3]| CollisionObject {
            id: id.into(),
            kind: "occupied".into(),
            primitive: SolidPrimitive { r#type: SolidPrimitive::BOX, dimensions: size.to_vec(), ..Default::default() },
            pose: Pose { position: Point { x: p[0], y: p[1], z: p[2] }, orientation: Quaternion::IDENTITY },
        };
        // A fruit 15 cm beside the target: three voxels of its surface (the fit 5 mm off), a
        // leaflet voxel 4.5 cm from its centre (its far corner beyond the 2 cm shell), and a
        // stem's run through it (longer than PUSHABLE_SIZE: structure, never filtered).
        let f = [1.0, 2.15, 3.0];
        let sensed = PlanningScene {
            objects: vec![
                cube("surface/a", [1.0, 2.15 - 0.03, 3.0], [0.01; 3]),
                cube("surface/b", [1.0 + 0.025, 2.155, 3.0], [0.01; 3]),
                cube("surface/c", [1.0, 2.15, 3.0 + 0.035], [0.01, 0.02, 0.01]),
                cube("leaflet", [1.0, 2.15 + 0.045, 3.0], [0.01; 3]),
                cube("stem", [1.0, 2.15, 3.0], [0.01, 0.01, 0.2]),
            ],
            ..Default::default()
        };
        let seen = [
            Seen { id: "t".into(), center: c, radius: r, ripe: 1.0 },
            Seen { id: "9".into(), center: f, radius: 0.03, ripe: 0.0 },
            // A track where the depth shows nothing (a fruit picked since, or seen in colour only).
            Seen { id: "12".into(), center: [1.0, 2.5, 3.0], radius: 0.03, ripe: 1.0 },
        ];
        let out = with_target(&sensed, c, r, &seen);
        let got: Vec<(&str, &str)> = out.objects.iter().map(|o| (o.id.as_str(), o.kind.as_str())).collect();
        assert_eq!(
            got,
            [("leaflet", "occupied"), ("stem", "occupied"), ("perceived/9", "fruit"), (TARGET_OBJECT, "fruit")]
        );
        assert_eq!(out.objects[2].primitive.r#type, SolidPrimitive::SPHERE);
        assert_eq!(out.objects[2].primitive.dimensions, vec![0.03]);
        // Without the fruit map the voxels stay.
        assert_eq!(with_target(&sensed, c, r, &[]).objects.len(), 6);
    }
}
