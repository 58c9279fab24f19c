//! Ground truth on the bus: the world's answers that judges and viewers read and the
//! algorithm layer must not (the fruit list, the handed-over target and its planning scene,
//! contacts, plant damage, the cameras' label images, the FMUs' signal dumps, the viewers'
//! scene markers, the world's moved objects on their way to the sensor FMUs). With the bus sealed ([`crate::Bus::seal_ground_truth`]), a node that
//! reads one of them during its step fails the run, naming the node and the topic.

/// Ground-truth topics by name.
pub const TOPICS: [&str; 7] = [
    "/fruits",
    "/target_fruit",
    "/planning_scene",
    "/collision",
    "/plant_damage",
    "/scene/markers",
    "/scene/fruit_markers",
];

/// Whether `topic` carries ground truth: one of [`TOPICS`], a camera's label image
/// (`.../labels`), the world's moved objects (`.../moved_objects`, the FMU-to-FMU route to
/// the sensors), or an FMU's signal dump (`/fmu/...`, e.g. the chassis' true pose).
pub fn is_ground_truth(topic: &str) -> bool {
    TOPICS.contains(&topic)
        || topic.ends_with("/labels")
        || topic.ends_with("/moved_objects")
        || topic.starts_with("/fmu/")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn world_answers_are_ground_truth_and_sensors_are_not() {
        for t in [
            "/fruits",
            "/target_fruit",
            "/planning_scene",
            "/collision",
            "/plant_damage",
            "/camera_left/labels",
            "/world/moved_objects",
            "/fmu/chassis/signals",
        ] {
            assert!(is_ground_truth(t), "{t}");
        }
        for t in [
            "/camera_left/color/image_raw",
            "/points",
            "/odom",
            "/mapping/planning_scene",
            "/perception/fruit_map",
            "/tf",
        ] {
            assert!(!is_ground_truth(t), "{t}");
        }
    }
}
