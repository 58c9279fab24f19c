//! What a recording keeps: a profile, topic includes and excludes, and per-topic decimation.
//!
//! Point clouds and images are nearly all of a run's bytes (84-86 % raw, 99 % compressed),
//! while judges and most analyses need the commands, states and events. Profiles:
//! - `full`: every message;
//! - `standard` (benchmarks' default): every message except point clouds and images (one
//!   every 5 s: a trial stays under 5 MB), IMU samples (50 Hz), the fruit list (once: it
//!   rarely changes) and the FMUs' signals (10 Hz);
//! - `judge`: what the judges read (harvest and navigation status and plans, collision
//!   states, run status) and the world's and chassis' ground-truth signals at 10 Hz;
//! - every profile but `none` keeps the viewer topics (`/robot_description`, the greenhouse
//!   markers): they are published once and again only on change, so a recording opens in
//!   Foxglove with the robot and the greenhouse drawn, for a few hundred kilobytes;
//! - `none`: no messages (the file keeps its metadata).
//!
//! Decimation keeps a message when at least the period has passed since the last one kept on
//! that topic (simulation time), so it is deterministic.

use serde::Deserialize;
use std::collections::BTreeMap;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Profile {
    #[default]
    Full,
    Standard,
    Judge,
    None,
}

impl Profile {
    /// The name `--record` and `[recording] profile` take.
    pub fn name(self) -> &'static str {
        match self {
            Profile::Full => "full",
            Profile::Standard => "standard",
            Profile::Judge => "judge",
            Profile::None => "none",
        }
    }
}

impl std::str::FromStr for Profile {
    type Err = String;
    fn from_str(s: &str) -> Result<Profile, String> {
        match s {
            "full" => Ok(Profile::Full),
            "standard" => Ok(Profile::Standard),
            "judge" => Ok(Profile::Judge),
            "none" => Ok(Profile::None),
            other => Err(format!("recording profile {other:?}: expected full, standard, judge or none")),
        }
    }
}

/// What happens to a topic's messages.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Rule {
    Keep,
    Drop,
    /// The first message only.
    Once,
    /// At most one message per this many seconds of simulation time.
    Every(f64),
}

/// `[recording]` of a scenario, and the CLI's `--record`.
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecordPolicy {
    #[serde(default)]
    pub profile: Profile,
    /// Topics kept whatever the profile says (a trailing `*` matches a prefix).
    #[serde(default)]
    pub include: Vec<String>,
    /// Topics dropped whatever the profile says (a trailing `*` matches a prefix).
    #[serde(default)]
    pub exclude: Vec<String>,
    /// Topic -> the shortest period between two kept messages \[s\], overriding the profile.
    #[serde(default)]
    pub decimate: BTreeMap<String, f64>,
}

fn matches(pattern: &str, topic: &str) -> bool {
    match pattern.strip_suffix('*') {
        Some(prefix) => topic.starts_with(prefix),
        None => pattern == topic,
    }
}

/// Period of point clouds and images in the `standard` profile \[s\].
pub const HEAVY_PERIOD: f64 = 5.0;
/// Period of IMU samples in the `standard` profile \[s\] (50 Hz: noise compresses badly).
pub const IMU_PERIOD: f64 = 0.02;
/// Period of maps that grow along the run (the fruit map, a sensed planning scene) in the
/// `standard` profile \[s\]: each message holds everything so far.
pub const MAP_PERIOD: f64 = 5.0;
const HEAVY_TYPES: [&str; 2] = ["sensor_msgs/msg/PointCloud2", "sensor_msgs/msg/Image"];
/// Period of per-frame detections in the `standard` profile \[s\].
pub const DETECTIONS_PERIOD: f64 = 1.0;
const MAP_TOPICS: [&str; 2] = ["/perception/fruit_map", "/mapping/planning_scene"];
const JUDGE_TOPICS: [&str; 6] =
    ["/harvest/status", "/harvest/plans", "/navigate/status", "/collision", "/plant_damage", "/agrisim/status"];
const GROUND_TRUTH_SIGNALS: [&str; 2] = ["/fmu/world/signals", "/fmu/chassis/signals"];
/// Published once or on change, for viewers: kept by every profile but `none`.
pub const VIEWER_TOPICS: [&str; 3] = ["/robot_description", "/scene/markers", "/scene/fruit_markers"];

impl RecordPolicy {
    pub fn profile(profile: Profile) -> RecordPolicy {
        RecordPolicy { profile, ..Default::default() }
    }

    /// Checks the values (periods positive and finite).
    pub fn validate(&self) -> Result<(), String> {
        for (topic, p) in &self.decimate {
            if !(p.is_finite() && *p > 0.0) {
                return Err(format!("[recording] decimate {topic:?}: period {p} s must be positive"));
            }
        }
        Ok(())
    }

    /// The rule for `topic` carrying `type_name`.
    pub fn rule(&self, topic: &str, type_name: &str) -> Rule {
        if self.exclude.iter().any(|p| matches(p, topic)) {
            return Rule::Drop;
        }
        if let Some(p) = self.decimate.iter().find(|(p, _)| matches(p, topic)).map(|(_, p)| *p) {
            return Rule::Every(p);
        }
        if self.include.iter().any(|p| matches(p, topic)) {
            return Rule::Keep;
        }
        let signals = topic.starts_with("/fmu/") && topic.ends_with("/signals");
        match self.profile {
            Profile::Full => Rule::Keep,
            Profile::None => Rule::Drop,
            _ if VIEWER_TOPICS.contains(&topic) => Rule::Keep,
            Profile::Standard if HEAVY_TYPES.contains(&type_name) => Rule::Every(HEAVY_PERIOD),
            Profile::Standard if MAP_TOPICS.contains(&topic) => Rule::Every(MAP_PERIOD),
            Profile::Standard if type_name == "vision_msgs/msg/Detection3DArray" => Rule::Every(DETECTIONS_PERIOD),
            Profile::Standard if topic == "/fruits" => Rule::Once,
            // The world's moved objects (to the sensors) change every step something is
            // carried: ten a second say where they went.
            Profile::Standard if type_name == "agrisim_msgs/msg/MovedObjects" => Rule::Every(0.1),
            Profile::Standard if type_name == "sensor_msgs/msg/Imu" => Rule::Every(IMU_PERIOD),
            Profile::Standard if signals => Rule::Every(0.1),
            Profile::Standard => Rule::Keep,
            Profile::Judge if JUDGE_TOPICS.contains(&topic) => Rule::Keep,
            Profile::Judge if GROUND_TRUTH_SIGNALS.contains(&topic) => Rule::Every(0.1),
            Profile::Judge => Rule::Drop,
        }
    }
}

/// Applies a [`Rule`] to one topic's stream of messages.
#[derive(Clone, Debug)]
pub struct TopicFilter {
    rule: Rule,
    last_kept_ns: Option<i64>,
}

impl TopicFilter {
    pub fn new(rule: Rule) -> TopicFilter {
        TopicFilter { rule, last_kept_ns: None }
    }

    /// Whether the message at `t_ns` is kept (and remembered as kept).
    pub fn keep(&mut self, t_ns: i64) -> bool {
        let keep = match (self.rule, self.last_kept_ns) {
            (Rule::Keep, _) => true,
            (Rule::Drop, _) => false,
            (Rule::Once, last) => last.is_none(),
            (Rule::Every(_), None) => true,
            // 1 ns slack: periods in seconds need not be whole nanoseconds.
            (Rule::Every(p), Some(last)) => t_ns - last >= (p * 1e9).round() as i64 - 1,
        };
        if keep {
            self.last_kept_ns = Some(t_ns);
        }
        keep
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profiles_and_overrides() {
        let std = RecordPolicy::profile(Profile::Standard);
        assert_eq!(std.rule("/points", "sensor_msgs/msg/PointCloud2"), Rule::Every(5.0));
        assert_eq!(std.rule("/cmd_vel", "geometry_msgs/msg/Twist"), Rule::Keep);
        assert_eq!(std.rule("/fruits", "geometry_msgs/msg/PoseArray"), Rule::Once);
        assert_eq!(std.rule("/world/moved_objects", "agrisim_msgs/msg/MovedObjects"), Rule::Every(0.1));
        assert_eq!(std.rule("/mapping/planning_scene", "agrisim_msgs/msg/PlanningScene"), Rule::Every(MAP_PERIOD));
        assert_eq!(std.rule("/imu", "sensor_msgs/msg/Imu"), Rule::Every(0.02));
        assert_eq!(std.rule("/fmu/imu/signals", "agrisim_msgs/msg/Signals"), Rule::Every(0.1));
        let judge = RecordPolicy::profile(Profile::Judge);
        assert_eq!(judge.rule("/collision", "agrisim_msgs/msg/CollisionState"), Rule::Keep);
        assert_eq!(judge.rule("/plant_damage", "agrisim_msgs/msg/PlantDamage"), Rule::Keep);
        assert_eq!(judge.rule("/world/moved_objects", "agrisim_msgs/msg/MovedObjects"), Rule::Drop);
        assert_eq!(judge.rule("/imu", "sensor_msgs/msg/Imu"), Rule::Drop);
        assert_eq!(RecordPolicy::profile(Profile::None).rule("/collision", "x"), Rule::Drop);
        for topic in VIEWER_TOPICS {
            for p in [Profile::Full, Profile::Standard, Profile::Judge] {
                assert_eq!(RecordPolicy::profile(p).rule(topic, "visualization_msgs/msg/MarkerArray"), Rule::Keep);
            }
            assert_eq!(RecordPolicy::profile(Profile::None).rule(topic, "std_msgs/msg/String"), Rule::Drop);
        }
        let custom = RecordPolicy {
            profile: Profile::None,
            include: vec!["/camera/*".into()],
            exclude: vec!["/camera/labels".into()],
            decimate: BTreeMap::from([("/imu".into(), 0.05)]),
        };
        assert_eq!(custom.rule("/camera/color/image_raw", "sensor_msgs/msg/Image"), Rule::Keep);
        assert_eq!(custom.rule("/camera/labels", "sensor_msgs/msg/Image"), Rule::Drop);
        assert_eq!(custom.rule("/imu", "sensor_msgs/msg/Imu"), Rule::Every(0.05));
        assert!("partial".parse::<Profile>().unwrap_err().contains("full, standard, judge or none"));
    }

    #[test]
    fn decimation_on_simulation_time() {
        let mut f = TopicFilter::new(Rule::Every(1.0));
        let kept: Vec<i64> = (0..35).map(|k| k * 100_000_000).filter(|&t| f.keep(t)).collect();
        assert_eq!(kept, [0, 1_000_000_000, 2_000_000_000, 3_000_000_000]);
        let mut once = TopicFilter::new(Rule::Once);
        assert!(once.keep(5) && !once.keep(6));
    }
}
