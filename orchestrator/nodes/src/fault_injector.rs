//! Publishes a scenario's injected raw messages once each at their time: corrupt or
//! unexpected input on a topic, to show the system reports it and keeps its log readable.

use super::Node;
use agrisim_bus::Bus;
use agrisim_error::Result;
use serde::Deserialize;

/// A raw message to publish once, e.g. a corrupt command, to test how the system copes.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Injection {
    pub t: f64,
    pub topic: String,
    /// ROS 2 type recorded for the bytes (`pkg/msg/Type`).
    #[serde(rename = "type")]
    pub type_name: String,
    /// The bytes, as hex.
    pub hex: String,
}

impl Injection {
    pub fn bytes(&self) -> Result<Vec<u8>> {
        let h = self.hex.trim();
        if !h.len().is_multiple_of(2) || !h.bytes().all(|b| b.is_ascii_hexdigit()) {
            return Err(agrisim_error::err!(
                "inject on {} at t={}: hex {:?} is not an even number of hex digits",
                self.topic,
                self.t,
                self.hex
            ));
        }
        Ok((0..h.len()).step_by(2).map(|i| u8::from_str_radix(&h[i..i + 2], 16).expect("checked hex")).collect())
    }
}

pub struct FaultInjector {
    pending: Vec<(i64, Injection)>,
}

impl FaultInjector {
    pub fn new(injections: &[Injection]) -> FaultInjector {
        let mut pending: Vec<(i64, Injection)> =
            injections.iter().map(|i| ((i.t * 1e9).round() as i64, i.clone())).collect();
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
