//! Publication schedule on simulation time: a message port publishes at k * period, whatever
//! the importer's communication step is (FMI 3 clocks are too rarely supported to rely on).

/// Tracks which publication instants have passed, in integer nanoseconds (no float drift).
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Schedule {
    period_ns: i64,
    next: i64,
}

impl Schedule {
    pub fn new(rate_hz: f64, start_time: f64) -> Result<Schedule, String> {
        if !(rate_hz.is_finite() && rate_hz > 0.0) {
            return Err(format!("publication rate must be positive and finite, got {rate_hz}"));
        }
        let period_ns = (1e9 / rate_hz).round() as i64;
        let period_ns = period_ns.max(1);
        Ok(Schedule { period_ns, next: to_ns(start_time).div_euclid(period_ns) })
    }

    /// The latest publication instant (ns) in (previous call, t], if any.
    pub fn due(&mut self, t: f64) -> Option<i64> {
        let now = to_ns(t);
        if self.next * self.period_ns > now {
            return None;
        }
        let k = now.div_euclid(self.period_ns);
        self.next = k + 1;
        Some(k * self.period_ns)
    }
}

/// Seconds to integer nanoseconds, rounded (communication points are multiples of ns).
pub fn to_ns(t: f64) -> i64 {
    (t * 1e9).round() as i64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ten_hz_on_a_fifty_hz_grid() {
        let mut s = Schedule::new(10.0, 0.0).unwrap();
        let mut hits = vec![];
        for k in 0..=50 {
            if let Some(ns) = s.due(k as f64 * 0.02) {
                hits.push(ns);
            }
        }
        let want: Vec<i64> = (0..=10).map(|i| i * 100_000_000).collect();
        assert_eq!(hits, want);
    }

    #[test]
    fn coarse_steps_publish_latest_instant_once() {
        let mut s = Schedule::new(10.0, 0.0).unwrap();
        assert_eq!(s.due(0.0), Some(0));
        assert_eq!(s.due(0.35), Some(300_000_000));
        assert_eq!(s.due(0.38), None);
        assert_eq!(s.due(0.4), Some(400_000_000));
    }
}
