//! The harvest task for an external harvest node (`--external harvest`): which fruit of the
//! world's list to harvest, sent once at the start on `/harvest/task` (std_msgs/Float64, the
//! index), as the benchmark hands the built-in node its target. Nothing else is given.

use agrisim_bus::{Bus, Node};
use agrisim_error::Result;
use agrisim_msgs::std_msgs::Float64;

pub const TASK: &str = "/harvest/task";

pub struct TaskPublisher {
    fruit_index: Option<usize>,
}

impl TaskPublisher {
    pub fn new(fruit_index: usize) -> TaskPublisher {
        TaskPublisher { fruit_index: Some(fruit_index) }
    }
}

impl Node for TaskPublisher {
    fn name(&self) -> &str {
        "harvest_task"
    }

    fn step(&mut self, t_ns: i64, bus: &mut Bus) -> Result<()> {
        if let Some(i) = self.fruit_index.take() {
            bus.publish(TASK, t_ns, &Float64 { data: i as f64 });
        }
        Ok(())
    }
}
