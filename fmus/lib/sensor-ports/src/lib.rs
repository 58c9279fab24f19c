//! The ports every ray-casting sensor FMU on the robot base has (LiDAR, camera): the scene
//! parameters, the sensor's mount on base_link, the robot's own base box and the base pose
//! inputs. Declared once ([`sensor_variables!`](crate::sensor_variables)) and read once
//! ([`SensorPorts`]), so the sensors see the same scene and base box from the same scenario
//! text and name and check these parameters the same way.
//!
//! FMU-side glue between the FMI export layer (`agrisim_fmi`) and the scene
//! (`agrisim_scene`, `agrisim_raycast`), kept out of them so that scene generation does not
//! depend on the export layer. The world FMU declares the scene and base ports from the same
//! constants.

pub mod moved;
pub mod robot;

pub use moved::MovedInput;

use agrisim_fmi::{checked_f64, InPort, Start, Store, Var};
use agrisim_msgs::agrisim::MovedObjects;
use agrisim_msgs::Message;
use agrisim_raycast::cast_scene::{load_cached, CastScene};
use agrisim_robot::model::Coords;
use agrisim_scene::Placement;
use std::sync::Arc;

#[doc(hidden)]
pub use agrisim_fmi as __fmi;

/// A sensor's `variables!` table with the shared ports spliced in, in this order: `scene`,
/// `scene_seed`; the sensor's own `params`; `mount_x/y/z`, `mount_roll/pitch/yaw` (of
/// `$link`, default position `($x, $y, $z)`); `base_length/width/height/clearance`;
/// the inputs `base_x`, `base_y`, `base_yaw`; the sensor's own `ports`; the robot body's
/// parameter `robot_links` and inputs `lift_position`, `left_q1..7`, `left_finger_width`,
/// `right_q1..7`, `right_finger_width` (as the world FMU's, see [`robot`]). Also defines
/// `SENSOR_PORTS` ([`SensorPorts`]) for reading them. Each own entry ends with a comma.
#[macro_export]
macro_rules! sensor_variables {
    ($vis:vis $table:ident {
        mount: $link:literal ($x:expr, $y:expr, $z:expr),
        params: { $($params:tt)* },
        ports: { $($ports:tt)* } $(,)?
    }) => {
        $crate::__fmi::variables! { $vis $table {
            SCENE = $crate::SCENE,
            SCENE_SEED = $crate::SCENE_SEED,
            $($params)*
            MOUNT_X = $crate::mount_param("mount_x", $x, "m").desc(concat!($link, " position on base_link")),
            MOUNT_Y = $crate::mount_param("mount_y", $y, "m"),
            MOUNT_Z = $crate::mount_param("mount_z", $z, "m"),
            MOUNT_ROLL = $crate::mount_param("mount_roll", 0.0, "rad")
                .desc(concat!($link, " orientation on base_link, roll-pitch-yaw about fixed axes (URDF); 0 = facing along base_link x")),
            MOUNT_PITCH = $crate::mount_param("mount_pitch", 0.0, "rad"),
            MOUNT_YAW = $crate::mount_param("mount_yaw", 0.0, "rad"),
            BASE_LENGTH = $crate::BASE_BOX[0],
            BASE_WIDTH = $crate::BASE_BOX[1],
            BASE_HEIGHT = $crate::BASE_BOX[2],
            BASE_CLEARANCE = $crate::BASE_BOX[3],
            BASE_X = $crate::BASE_POSE[0],
            BASE_Y = $crate::BASE_POSE[1],
            BASE_YAW = $crate::BASE_POSE[2],
            $($ports)*
            ROBOT_LINKS = $crate::robot::ROBOT_LINKS,
            LIFT_POSITION = $crate::robot::LIFT_POSITION,
            LEFT_Q1 = $crate::robot::ARM_JOINTS[0][0],
            LEFT_Q2 = $crate::robot::ARM_JOINTS[0][1],
            LEFT_Q3 = $crate::robot::ARM_JOINTS[0][2],
            LEFT_Q4 = $crate::robot::ARM_JOINTS[0][3],
            LEFT_Q5 = $crate::robot::ARM_JOINTS[0][4],
            LEFT_Q6 = $crate::robot::ARM_JOINTS[0][5],
            LEFT_Q7 = $crate::robot::ARM_JOINTS[0][6],
            LEFT_FINGER_WIDTH = $crate::robot::FINGER_WIDTHS[0],
            RIGHT_Q1 = $crate::robot::ARM_JOINTS[1][0],
            RIGHT_Q2 = $crate::robot::ARM_JOINTS[1][1],
            RIGHT_Q3 = $crate::robot::ARM_JOINTS[1][2],
            RIGHT_Q4 = $crate::robot::ARM_JOINTS[1][3],
            RIGHT_Q5 = $crate::robot::ARM_JOINTS[1][4],
            RIGHT_Q6 = $crate::robot::ARM_JOINTS[1][5],
            RIGHT_Q7 = $crate::robot::ARM_JOINTS[1][6],
            RIGHT_FINGER_WIDTH = $crate::robot::FINGER_WIDTHS[1],
            MOVED_OBJECTS = $crate::MOVED_OBJECTS[0],
            MOVED_OBJECTS_SEQ = $crate::MOVED_OBJECTS[1],
        }}

        /// Readers of the shared sensor ports of this table.
        #[allow(dead_code)]
        $vis const SENSOR_PORTS: $crate::SensorPorts = $crate::SensorPorts {
            vars: $table,
            scene: SCENE,
            scene_seed: SCENE_SEED,
            mount: [MOUNT_X, MOUNT_Y, MOUNT_Z, MOUNT_ROLL, MOUNT_PITCH, MOUNT_YAW],
            base_box: [BASE_LENGTH, BASE_WIDTH, BASE_HEIGHT, BASE_CLEARANCE],
            base_pose: [BASE_X, BASE_Y, BASE_YAW],
            link: $link,
            robot_links: ROBOT_LINKS,
            lift: LIFT_POSITION,
            arms: [
                [LEFT_Q1, LEFT_Q2, LEFT_Q3, LEFT_Q4, LEFT_Q5, LEFT_Q6, LEFT_Q7],
                [RIGHT_Q1, RIGHT_Q2, RIGHT_Q3, RIGHT_Q4, RIGHT_Q5, RIGHT_Q6, RIGHT_Q7],
            ],
            widths: [LEFT_FINGER_WIDTH, RIGHT_FINGER_WIDTH],
            moved: [MOVED_OBJECTS, MOVED_OBJECTS_SEQ],
        };
    };
}

pub const SCENE: Var = Var::param("scene", Start::String(""))
    .desc("The keys of the scenario's [greenhouse] table as TOML (no header); empty = the default greenhouse");
pub const SCENE_SEED: Var = Var::param("scene_seed", Start::Int32(-1))
    .desc("Seed of the greenhouse generator; < 0 = the scene's own seed key (as the world FMU)");

/// A mount parameter (position or angle) with its default.
pub const fn mount_param(name: &'static str, start: f64, unit: &'static str) -> Var {
    Var::param(name, Start::Float64(start)).unit(unit)
}

/// The robot's own base box, a moving obstacle for the rays (as the world FMU has it).
pub const BASE_BOX: [Var; 4] = [
    Var::param("base_length", Start::Float64(1.2))
        .unit("m")
        .range(0.01, 20.0)
        .desc("Robot base box extent along base_link x"),
    Var::param("base_width", Start::Float64(0.9)).unit("m").range(0.01, 20.0),
    Var::param("base_height", Start::Float64(0.6)).unit("m").range(0.01, 20.0),
    Var::param("base_clearance", Start::Float64(0.05))
        .unit("m")
        .range(0.0, 5.0)
        .desc("Height of the box bottom above the floor (base_link is on the floor)"),
];

/// Inputs: the chassis' ground-truth pose of base_link in the map frame.
pub const BASE_POSE: [Var; 3] = [
    Var::input("base_x", 0.0).unit("m").desc("x of base_link in the map frame"),
    Var::input("base_y", 0.0).unit("m").desc("y of base_link in the map frame"),
    Var::input("base_yaw", 0.0).unit("rad").desc("Yaw of base_link in the map frame"),
];

/// MIME type of the world's `moved_objects` output and the sensors' input.
pub const MOVED_OBJECTS_MIME: &str = "application/x-ros2-cdr-frames; version=1; type=agrisim_msgs/msg/MovedObjects";

/// Input: the world FMU's `moved_objects` (agrisim_msgs/MovedObjects), so the sensor renders
/// pushed leaves and picked fruit where they are. Unconnected, the scene stays as grown.
pub const MOVED_OBJECTS: [Var; 2] = [
    Var::input_discrete("moved_objects", Start::Binary(&[]))
        .mime(MOVED_OBJECTS_MIME)
        .max_size(agrisim_fmi::port::frames_max_size(64 + 60 * 16384, 64))
        .desc("agrisim_msgs/MovedObjects from the world FMU's moved_objects (CDR frames): scene objects away from their grown placement (pushed leaves, picked fruit), rendered where they are; unconnected = the scene as grown"),
    Var::input_discrete("moved_objects_seq", Start::Int64(0)).desc("Sequence number of the newest message in moved_objects"),
];

/// Where a sensor is on base_link: position and fixed-axis roll-pitch-yaw (URDF).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Mount {
    pub translation: [f64; 3],
    pub roll: f64,
    pub pitch: f64,
    pub yaw: f64,
}

/// Indices of the shared ports in one sensor's table (made by [`sensor_variables!`](crate::sensor_variables)).
#[derive(Clone, Copy, Debug)]
pub struct SensorPorts {
    pub vars: &'static [Var],
    pub scene: usize,
    pub scene_seed: usize,
    /// mount_x, mount_y, mount_z, mount_roll, mount_pitch, mount_yaw.
    pub mount: [usize; 6],
    /// base_length, base_width, base_height, base_clearance.
    pub base_box: [usize; 4],
    /// base_x, base_y, base_yaw.
    pub base_pose: [usize; 3],
    /// The sensor's own URDF link (its housing, which its rays start inside).
    pub link: &'static str,
    pub robot_links: usize,
    pub lift: usize,
    /// `<side>_q1..7`, left then right.
    pub arms: [[usize; 7]; 2],
    /// `<side>_finger_width`, left then right.
    pub widths: [usize; 2],
    /// `moved_objects` and its counter.
    pub moved: [usize; 2],
}

impl SensorPorts {
    /// The (cached) scene of the `scene` and `scene_seed` parameters.
    pub fn scene(&self, io: &Store) -> Result<Arc<CastScene>, String> {
        load_cached(io.string(self.scene), io.i32(self.scene_seed))
    }

    /// The mount parameters (each must be finite).
    pub fn mount(&self, io: &Store) -> Result<Mount, String> {
        let [x, y, z, roll, pitch, yaw] = self.mount.map(|i| checked_f64(io, self.vars, i, |_| true, "finite"));
        Ok(Mount { translation: [x?, y?, z?], roll: roll?, pitch: pitch?, yaw: yaw? })
    }

    /// [length, width, height, clearance] of the base box, as
    /// [`base_box`](agrisim_raycast::cast_scene::base_box) takes it: extents positive, clearance >= 0.
    pub fn base_box(&self, io: &Store) -> Result<[f64; 4], String> {
        let [l, w, h, c] = self.base_box;
        let positive = |i| checked_f64(io, self.vars, i, |v| v > 0.0, "positive");
        Ok([positive(l)?, positive(w)?, positive(h)?, checked_f64(io, self.vars, c, |v| v >= 0.0, ">= 0")?])
    }

    /// The robot's configuration inputs when `robot_links` is on (None: the base box only).
    /// Values must be finite; joints beyond their limits are clamped by the FK.
    pub fn coords(&self, io: &Store) -> Result<Option<Coords>, String> {
        if !io.bool(self.robot_links) {
            return Ok(None);
        }
        let get = |i: usize| {
            let v = io.f64(i);
            if v.is_finite() && v.abs() < 1e3 {
                Ok(v)
            } else {
                Err(format!("input {} = {v} is not finite or beyond 1e3", self.vars[i].name))
            }
        };
        let mut c = Coords { lift: get(self.lift)?, ..Coords::default() };
        for side in 0..2 {
            for (q, &i) in c.arms[side].iter_mut().zip(&self.arms[side]) {
                *q = get(i)?;
            }
            c.widths[side] = get(self.widths[side])?;
        }
        Ok(Some(c))
    }

    /// The robot body for this sensor (ids from `first_id`, the scene's object count).
    pub fn robot_body(&self, io: &Store, first_id: u32) -> Result<robot::RobotBody, String> {
        robot::RobotBody::new(first_id, self.base_box(io)?, self.link)
    }

    /// The newest `moved_objects` message that `port` has not taken yet, as (object id,
    /// placement) pairs (None: nothing new). Ids must be ascending scene ids (below
    /// `object_count`) and poses finite, with a non-zero quaternion (renormalized).
    pub fn moved_objects(
        &self,
        io: &Store,
        port: &mut InPort,
        object_count: usize,
    ) -> Result<Option<Vec<(u32, Placement)>>, String> {
        let name = self.vars[self.moved[0]].name;
        let Some(cdr) = port.take(io, name)?.pop() else { return Ok(None) };
        let msg =
            MovedObjects::from_cdr(&cdr).map_err(|e| format!("input {name}: not an agrisim_msgs/MovedObjects: {e}"))?;
        if msg.ids.len() != msg.poses.len() {
            return Err(format!("input {name}: {} ids but {} poses", msg.ids.len(), msg.poses.len()));
        }
        let mut out = Vec::with_capacity(msg.ids.len());
        for (k, (&id, p)) in msg.ids.iter().zip(&msg.poses).enumerate() {
            if id as usize >= object_count || (k > 0 && id <= msg.ids[k - 1]) {
                return Err(format!(
                    "input {name}: object id {id} (entry {k}) is not an ascending id of the scene's {object_count} objects"
                ));
            }
            let (t, q) = (&p.position, &p.orientation);
            let all = [t.x, t.y, t.z, q.x, q.y, q.z, q.w];
            let norm = (q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w).sqrt();
            if all.iter().any(|v| !v.is_finite() || v.abs() > 1e6) || norm < 1e-9 {
                return Err(format!("input {name}: the pose of object {id} is not finite or has no rotation: {p:?}"));
            }
            let rotation = [q.x / norm, q.y / norm, q.z / norm, q.w / norm];
            out.push((id, Placement { translation: [t.x, t.y, t.z], rotation }));
        }
        Ok(Some(out))
    }

    /// The base pose inputs (x, y, yaw); refused when not finite or beyond 1e6.
    pub fn base_pose(&self, io: &Store) -> Result<(f64, f64, f64), String> {
        let [x, y, yaw] = self.base_pose.map(|i| io.f64(i));
        if [x, y, yaw].iter().all(|v| v.is_finite() && v.abs() < 1e6) {
            Ok((x, y, yaw))
        } else {
            Err(format!("robot pose input (base_x, base_y, base_yaw) = ({x}, {y}, {yaw}) is not finite or beyond 1e6"))
        }
    }
}

#[cfg(test)]
mod tests {
    use agrisim_fmi::{Start, Store, Var};

    crate::sensor_variables! { VARIABLES {
        mount: "test_link" (0.1, 0.2, 0.3),
        params: { OWN = Var::param("own", Start::Int32(0)), },
        ports: { OUT = Var::output_discrete("out", Start::Int32(0)), },
    }}

    #[test]
    fn shared_ports_are_spliced_in_order_around_the_sensors_own() {
        let names: Vec<&str> = VARIABLES.iter().map(|v| v.name).collect();
        assert_eq!(
            names,
            [
                "scene",
                "scene_seed",
                "own",
                "mount_x",
                "mount_y",
                "mount_z",
                "mount_roll",
                "mount_pitch",
                "mount_yaw",
                "base_length",
                "base_width",
                "base_height",
                "base_clearance",
                "base_x",
                "base_y",
                "base_yaw",
                "out",
                "robot_links",
                "lift_position",
                "left_q1",
                "left_q2",
                "left_q3",
                "left_q4",
                "left_q5",
                "left_q6",
                "left_q7",
                "left_finger_width",
                "right_q1",
                "right_q2",
                "right_q3",
                "right_q4",
                "right_q5",
                "right_q6",
                "right_q7",
                "right_finger_width",
                "moved_objects",
                "moved_objects_seq"
            ]
        );
        assert_eq!((OWN, OUT, SENSOR_PORTS.base_pose), (2, 16, [13, 14, 15]));
        assert_eq!(
            (SENSOR_PORTS.robot_links, SENSOR_PORTS.lift, SENSOR_PORTS.arms[1][6], SENSOR_PORTS.widths),
            (17, 18, 33, [26, 34])
        );
        assert_eq!(SENSOR_PORTS.link, "test_link");
        assert_eq!(VARIABLES[MOUNT_X].description, "test_link position on base_link");
    }

    #[test]
    fn robot_inputs_read_as_coords_unless_links_are_off() {
        let mut io = Store::new(VARIABLES);
        let c = SENSOR_PORTS.coords(&io).unwrap().unwrap();
        assert_eq!(c, crate::robot::Coords::default());
        io.set_f64(LEFT_Q3, 0.4);
        io.set_f64(RIGHT_FINGER_WIDTH, 0.02);
        io.set_f64(LIFT_POSITION, 0.3);
        let c = SENSOR_PORTS.coords(&io).unwrap().unwrap();
        assert_eq!((c.arms[0][2], c.widths[1], c.lift), (0.4, 0.02, 0.3));
        io.set_f64(RIGHT_Q5, f64::NAN);
        assert!(SENSOR_PORTS.coords(&io).unwrap_err().contains("right_q5"));
        *io.value_mut(ROBOT_LINKS) = agrisim_fmi::Value::Boolean(false);
        assert_eq!(SENSOR_PORTS.coords(&io).unwrap(), None);
    }

    #[test]
    fn readers_check_values_and_name_the_variable() {
        let mut io = Store::new(VARIABLES);
        let m = SENSOR_PORTS.mount(&io).unwrap();
        assert_eq!((m.translation, m.roll), ([0.1, 0.2, 0.3], 0.0));
        assert_eq!(SENSOR_PORTS.base_box(&io).unwrap(), [1.2, 0.9, 0.6, 0.05]);
        io.set_f64(MOUNT_PITCH, f64::NAN);
        assert!(SENSOR_PORTS.mount(&io).unwrap_err().contains("mount_pitch must be finite"));
        io.set_f64(BASE_WIDTH, 0.0);
        assert!(SENSOR_PORTS.base_box(&io).unwrap_err().contains("base_width must be positive"));
        io.set_f64(BASE_Y, 2.0e6);
        assert!(SENSOR_PORTS.base_pose(&io).unwrap_err().contains("not finite or beyond 1e6"));
        io.set_f64(BASE_Y, -3.0);
        assert_eq!(SENSOR_PORTS.base_pose(&io).unwrap(), (0.0, -3.0, 0.0));
    }
}
