//! `--realtime [FACTOR]`: holds the run back so simulated time advances at FACTOR times the
//! wall clock (1 = real time), so a person can follow it in a viewer. Independent of any
//! bridge; it only sleeps: it publishes nothing and reads nothing, so the recording, the
//! judges' results and every message are the same with or without it.
//!
//! It runs as a node (at every message instant, 10 Hz by default: the pace is kept to one
//! exchange period). The schedule is anchored at the first instant: simulated time t is due
//! at wall time w0 + (t - t0) / FACTOR. A run that falls behind (a slow step) does not sleep
//! and does not rush to catch up beyond that schedule.

use super::Node;
use agrisim_bus::Bus;
use agrisim_error::{err, Result};
use std::time::{Duration, Instant};

/// The schedule alone, with the wall clock given in: what [`RealtimePacer`] sleeps, testable
/// without a clock.
#[derive(Clone, Debug)]
pub struct Pace {
    factor: f64,
    /// (simulated ns, wall time) of the first instant.
    origin: Option<(i64, Duration)>,
}

impl Pace {
    /// `factor`: simulated seconds per wall second (> 0, finite).
    pub fn new(factor: f64) -> Result<Pace> {
        if !(factor.is_finite() && factor > 0.0) {
            return Err(err!("--realtime {factor}: the factor must be a positive number (1 = real time)"));
        }
        Ok(Pace { factor, origin: None })
    }

    pub fn factor(&self) -> f64 {
        self.factor
    }

    /// How long to wait at simulated time `t_ns` when the wall clock reads `now` (any fixed
    /// origin): zero at the first call and whenever the run is late.
    pub fn delay(&mut self, t_ns: i64, now: Duration) -> Duration {
        let (t0, w0) = *self.origin.get_or_insert((t_ns, now));
        let due = w0 + Duration::from_nanos(((t_ns - t0).max(0) as f64 / self.factor).round() as u64);
        due.saturating_sub(now)
    }
}

/// The node: sleeps for [`Pace::delay`] on the process's monotonic clock.
pub struct RealtimePacer {
    pace: Pace,
    start: Instant,
}

impl RealtimePacer {
    pub fn new(factor: f64) -> Result<RealtimePacer> {
        Ok(RealtimePacer { pace: Pace::new(factor)?, start: Instant::now() })
    }
}

impl Node for RealtimePacer {
    fn name(&self) -> &str {
        "realtime_pacer"
    }

    fn step(&mut self, t_ns: i64, _bus: &mut Bus) -> Result<()> {
        let wait = self.pace.delay(t_ns, self.start.elapsed());
        if !wait.is_zero() {
            std::thread::sleep(wait);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ms(v: u64) -> Duration {
        Duration::from_millis(v)
    }

    #[test]
    fn waits_until_simulated_time_is_due_at_the_factor() {
        // Real time: the first instant (t = 2 s) anchors the schedule at wall 5 s.
        let mut p = Pace::new(1.0).unwrap();
        assert_eq!(p.delay(2_000_000_000, ms(5_000)), Duration::ZERO);
        // 0.1 s simulated later, 30 ms of wall time have passed: wait 70 ms.
        assert_eq!(p.delay(2_100_000_000, ms(5_030)), ms(70));
        // Late (a slow step): no wait, and the schedule stays where it was.
        assert_eq!(p.delay(2_200_000_000, ms(5_350)), Duration::ZERO);
        assert_eq!(p.delay(2_500_000_000, ms(5_400)), ms(100));
        // Twice real time: 1 s simulated is due after 0.5 s.
        let mut fast = Pace::new(2.0).unwrap();
        assert_eq!(fast.delay(0, ms(0)), Duration::ZERO);
        assert_eq!(fast.delay(1_000_000_000, ms(100)), ms(400));
        // Slow motion: a tenth of real time.
        let mut slow = Pace::new(0.1).unwrap();
        slow.delay(0, ms(0));
        assert_eq!(slow.delay(100_000_000, ms(0)), ms(1_000));
    }

    #[test]
    fn bad_factors_are_refused_with_the_flag_named() {
        for f in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let e = Pace::new(f).unwrap_err().to_string();
            assert!(e.contains("--realtime"), "{e}");
        }
    }
}
