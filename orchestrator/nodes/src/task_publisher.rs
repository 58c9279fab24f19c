//! The harvest task for an external harvest node (`--external harvest`): which fruit of the
//! world's list to harvest, sent once at the start on `/harvest/task` (std_msgs/Float64, the
//! index), as a benchmark hands the built-in node its target. Nothing else is given.

use agrisim_bus::{Bus, Node};
use agrisim_error::Result;
use agrisim_msgs::std_msgs::Float64;

pub struct TaskPublisher {
    fruit_index: Option<usize>,
}

impl TaskPublisher {
    pub const TOPIC: &'static str = "/harvest/task";

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
            bus.publish(Self::TOPIC, t_ns, &Float64 { data: i as f64 });
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
    }
}
