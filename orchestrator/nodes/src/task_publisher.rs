//! The harvest task for an external harvest node (`--external harvest`), sent once at the
//! start, as a benchmark hands the built-in node its task. Nothing else is given:
//! * with ground truth, which fruit of the world's list to harvest: `/harvest/task`
//!   (std_msgs/Float64, the index);
//! * by sight, the stretch of row to find a ripe fruit in: `/harvest/task_region`
//!   (vision_msgs/Detection3DArray in the `map` frame, one detection with id `task_region`
//!   whose box is the region, axis-aligned: centre and size; no class, no score).

use agrisim_bus::{Bus, Node};
use agrisim_error::Result;
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::geometry_msgs::{Point, Pose, Quaternion, Vector3};
use agrisim_msgs::std_msgs::{Float64, Header};
use agrisim_msgs::vision_msgs::{BoundingBox3D, Detection3D, Detection3DArray};

/// What to send.
enum Task {
    Fruit(usize),
    /// x, y, z ranges in the map frame [m].
    Region([[f64; 2]; 3]),
}

pub struct TaskPublisher {
    task: Option<Task>,
}

impl TaskPublisher {
    pub const TOPIC: &'static str = "/harvest/task";
    pub const REGION_TOPIC: &'static str = "/harvest/task_region";
    /// Detection id of the region.
    pub const REGION_ID: &'static str = "task_region";

    /// Fruit `fruit_index` of the world's list.
    pub fn new(fruit_index: usize) -> TaskPublisher {
        TaskPublisher { task: Some(Task::Fruit(fruit_index)) }
    }

    /// A ripe fruit in the box of x, y, z ranges `region` (map frame) [m].
    pub fn region(region: [[f64; 2]; 3]) -> TaskPublisher {
        TaskPublisher { task: Some(Task::Region(region)) }
    }
}

/// The region as the message sends it.
fn region_message(stamp: Time, r: [[f64; 2]; 3]) -> Detection3DArray {
    let header = Header { stamp, frame_id: "map".into() };
    let c = r.map(|a| 0.5 * (a[0] + a[1]));
    let size = r.map(|a| a[1] - a[0]);
    Detection3DArray {
        header: header.clone(),
        detections: vec![Detection3D {
            header,
            results: vec![],
            bbox: BoundingBox3D {
                center: Pose { position: Point { x: c[0], y: c[1], z: c[2] }, orientation: Quaternion::IDENTITY },
                size: Vector3 { x: size[0], y: size[1], z: size[2] },
            },
            id: TaskPublisher::REGION_ID.into(),
        }],
    }
}

impl Node for TaskPublisher {
    fn name(&self) -> &str {
        "harvest_task"
    }

    fn step(&mut self, t_ns: i64, bus: &mut Bus) -> Result<()> {
        match self.task.take() {
            Some(Task::Fruit(i)) => bus.publish(Self::TOPIC, t_ns, &Float64 { data: i as f64 }),
            Some(Task::Region(r)) => bus.publish(Self::REGION_TOPIC, t_ns, &region_message(Time::from_nanos(t_ns), r)),
            None => {}
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use agrisim_msgs::Message;

    /// The task goes out once, at the first step, as the fruit's index.
    #[test]
    fn publishes_the_index_once() {
        let mut bus = Bus::default();
        let mut p = TaskPublisher::new(17);
        p.step(0, &mut bus).unwrap();
        let first = bus.latest(TaskPublisher::TOPIC).expect("published");
        assert_eq!(Float64::from_cdr(&first.cdr).unwrap().data, 17.0);
        p.step(100, &mut bus).unwrap();
        assert_eq!(bus.latest(TaskPublisher::TOPIC).unwrap().seq, 1, "nothing more after the first step");
        assert!(bus.latest(TaskPublisher::REGION_TOPIC).is_none());
    }

    /// By sight: the region once, as a box in the map frame, and no fruit index.
    #[test]
    fn publishes_the_region_once() {
        let mut bus = Bus::default();
        let mut p = TaskPublisher::region([[7.0, 8.0], [32.7, 34.0], [0.55, 1.75]]);
        p.step(5, &mut bus).unwrap();
        p.step(100, &mut bus).unwrap();
        let m = bus.latest(TaskPublisher::REGION_TOPIC).expect("published");
        assert_eq!(m.seq, 1);
        let a = Detection3DArray::from_cdr(&m.cdr).unwrap();
        assert_eq!(a.header.frame_id, "map");
        let [d] = a.detections.as_slice() else { panic!("one detection") };
        assert_eq!(d.id, TaskPublisher::REGION_ID);
        let (c, s) = (&d.bbox.center.position, &d.bbox.size);
        let lo_hi = |c: f64, s: f64| [c - 0.5 * s, c + 0.5 * s];
        for (got, want) in
            [lo_hi(c.x, s.x), lo_hi(c.y, s.y), lo_hi(c.z, s.z)].iter().zip([[7.0, 8.0], [32.7, 34.0], [0.55, 1.75]])
        {
            assert!((got[0] - want[0]).abs() < 1e-12 && (got[1] - want[1]).abs() < 1e-12, "{got:?} vs {want:?}");
        }
        assert!(bus.latest(TaskPublisher::TOPIC).is_none());
    }
}
