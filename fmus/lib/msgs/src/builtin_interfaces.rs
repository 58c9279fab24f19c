//! `builtin_interfaces`: ROS time.

use crate::message::ros_message;

ros_message! {
    /// `builtin_interfaces/msg/Time`: seconds plus nanoseconds in `[0, 1e9)`, also for
    /// negative times (-1.7 s = `{sec: -2, nanosec: 300_000_000}`).
    #[derive(Debug, Default, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize)]
    pub struct Time = "builtin_interfaces/msg/Time" {
        pub sec: i32,
        pub nanosec: u32,
    }
}

const NANOS_PER_SEC: i64 = 1_000_000_000;

impl Time {
    pub const fn new(sec: i32, nanosec: u32) -> Self {
        Self { sec, nanosec }
    }

    /// From integer nanoseconds, exact. Times beyond the `i32` seconds range (year 2038 /
    /// 68 years of simulation) saturate instead of wrapping.
    pub fn from_nanos(nanos: i64) -> Self {
        let sec = nanos.div_euclid(NANOS_PER_SEC);
        let nanosec = nanos.rem_euclid(NANOS_PER_SEC) as u32;
        if sec > i32::MAX as i64 {
            Self { sec: i32::MAX, nanosec: 999_999_999 }
        } else if sec < i32::MIN as i64 {
            Self { sec: i32::MIN, nanosec: 0 }
        } else {
            Self { sec: sec as i32, nanosec }
        }
    }

    /// From the orchestrator's integer time ticks (`ticks / ticks_per_second` seconds)
    /// without going through `f64`, so recorded stamps never drift. Exact whenever a tick
    /// is a whole number of nanoseconds (ticks_per_second divides 1e9); otherwise the
    /// nanoseconds are rounded down. Saturates like [`Time::from_nanos`].
    ///
    /// Panics if `ticks_per_second` is 0 (like integer division).
    pub fn from_ticks(ticks: i64, ticks_per_second: u64) -> Self {
        assert!(ticks_per_second > 0, "ticks_per_second must be positive");
        let tps = ticks_per_second as i128;
        let nanos = (ticks as i128 * NANOS_PER_SEC as i128).div_euclid(tps);
        Self::from_nanos(nanos.clamp(i64::MIN as i128, i64::MAX as i128) as i64)
    }

    /// Total nanoseconds (always fits: |sec| < 2^31 s = 2.1e18 ns).
    pub fn to_nanos(&self) -> i64 {
        self.sec as i64 * NANOS_PER_SEC + self.nanosec as i64
    }

    /// Seconds as `f64`, for display and plotting only.
    pub fn as_secs_f64(&self) -> f64 {
        self.sec as f64 + self.nanosec as f64 * 1e-9
    }
}

ros_message! {
    /// `builtin_interfaces/msg/Duration`: same layout and normalisation as [`Time`]
    /// (-1.7 s = `{sec: -2, nanosec: 300_000_000}`); e.g. a trajectory point's
    /// `time_from_start`.
    #[derive(Debug, Default, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
    pub struct Duration = "builtin_interfaces/msg/Duration" {
        pub sec: i32,
        pub nanosec: u32,
    }
}

impl Duration {
    pub const fn new(sec: i32, nanosec: u32) -> Self {
        Self { sec, nanosec }
    }

    /// From integer nanoseconds, exact; saturates like [`Time::from_nanos`].
    pub fn from_nanos(nanos: i64) -> Self {
        let t = Time::from_nanos(nanos);
        Self::new(t.sec, t.nanosec)
    }

    /// From seconds, rounded to the nearest nanosecond; `None` for a non-finite value.
    pub fn from_secs_f64(secs: f64) -> Option<Self> {
        if !secs.is_finite() {
            return None;
        }
        let nanos = (secs * NANOS_PER_SEC as f64).round();
        Some(Self::from_nanos(nanos.clamp(i64::MIN as f64, i64::MAX as f64) as i64))
    }

    /// Total nanoseconds. Uses the raw fields, so a non-normalised `nanosec >= 1e9`
    /// (invalid, but decodable) still gives a defined value.
    pub fn to_nanos(&self) -> i64 {
        self.sec as i64 * NANOS_PER_SEC + self.nanosec as i64
    }

    /// Seconds as `f64`.
    pub fn as_secs_f64(&self) -> f64 {
        self.sec as f64 + self.nanosec as f64 * 1e-9
    }
}
