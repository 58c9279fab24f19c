//! Publishes a scenario's injected raw messages once each at their time: corrupt or
//! unexpected input on a topic, to show the system reports it and keeps its log readable.

use super::Node;
use crate::bus::Bus;
use crate::error::Result;
use crate::scenario::Injection;

pub struct FaultInjector {
    pending: Vec<(i64, Injection)>,
}

impl FaultInjector {
    pub fn new(injections: &[Injection]) -> FaultInjector {
        let mut pending: Vec<(i64, Injection)> = injections.iter().map(|i| ((i.t * 1e9).round() as i64, i.clone())).collect();
        pending.sort_by_key(|(t, _)| *t);
        FaultInjector { pending }
    }
}

impl Node for FaultInjector {
    fn name(&self) -> &str {
        "fault_injector"
    }

    fn step(&mut self, t_ns: i64, bus: &mut Bus) -> Result<()> {
        while self.pending.first().is_some_and(|(t, _)| *t <= t_ns) {
            let (_, inj) = self.pending.remove(0);
            bus.publish_raw(&inj.topic, &inj.type_name, t_ns, inj.bytes()?);
        }
        Ok(())
    }
}
