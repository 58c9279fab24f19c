//! The camera's variable table. Scene parameters, mount, base box and base pose inputs are the
//! shared sensor ports (`agrisim_sensor_ports`, as the LiDAR FMU's), so all
//! sensors and the world see the same geometry from the same scenario text.

use crate::datasheet as ds;
use agrisim_fmi::{Start, Var};

pub const IMAGE_MIME: &str = "application/x-ros2-cdr-frames; version=1; type=sensor_msgs/msg/Image";
pub const CAMERA_INFO_MIME: &str = "application/x-ros2-cdr-frames; version=1; type=sensor_msgs/msg/CameraInfo";
pub const TF_MIME: &str = "application/x-ros2-cdr-frames; version=1; type=tf2_msgs/msg/TFMessage";

/// Room for a message's header, metadata and frame_id [bytes]: all of CameraInfo, and what
/// an Image adds to its pixels.
pub const HEADER_ROOM: usize = 4096;

/// Largest image side the camera accepts [px]: bounds the image ports' maxSize.
pub const MAX_SIDE: i32 = 4096;

/// maxSize of an image port with `bytes_per_pixel`: the largest image plus its header.
pub const fn image_max_size(bytes_per_pixel: usize) -> usize {
    let side = MAX_SIDE as usize;
    side * side * bytes_per_pixel + HEADER_ROOM
}

// camera_link (x forward, y left, z up; the optical frame is z forward, x right, y down
// relative to it) on the link `mount_parent`: by default the URDF's camera_joint, on the lift
// carriage (camera_link at (0.32, 0, 0.60 + lift) on base_link, agrisim_robot.urdf). The
// shared table's descriptions say "on base_link": the mount is in mount_parent's frame, which
// is base_link only when mount_parent says so.
agrisim_sensor_ports::sensor_variables! { pub VARIABLES {
  mount: "camera_link" (0.12, 0.0, 0.15),
  params: {
    MOUNT_PARENT = Var::param("mount_parent", Start::String("lift_link"))
        .desc("URDF link (agrisim_robot.urdf) the camera is mounted on; mount_x..mount_yaw are camera_link's pose in its frame, and the camera moves with it (posed from lift_position and the arm inputs by the robot's forward kinematics): base_link, lift_link (the lift carriage, default), <side>_hand or <side>_link7 (a wrist), or any other link"),
    LINK_FRAME = Var::param("link_frame", Start::String("camera_link"))
        .desc("TF name of the camera body frame (REP 103: x forward, y left, z up) that the mount places; a URDF link of that name is the camera's own housing, left out of its view"),
    ENVIRONMENT = Var::param("environment", Start::String(""))
        .desc("The keys of the scenario's [environment] table as TOML (no header): date, time, place, weather, render quality; empty = the fixed sun of sun_azimuth / sun_elevation / ambient. Changes images, never geometry"),
    RENDER_THREADS = Var::param("render_threads", Start::Int32(2))
        .desc("Threads rendering a frame, 1-64 (results do not depend on it)"),
    // --- sensor (RealSense D435i defaults) ---
    NOISE_SEED = Var::param("seed", Start::Int32(0)).desc("Seed of the depth noise (set per run by the orchestrator)"),
    FRAME_RATE = Var::param("frame_rate", Start::Float64(ds::FRAME_RATE)).unit("Hz").range(0.1, 1000.0)
        .desc("Frames per second of simulation time"),
    WIDTH = Var::param("width", Start::Int32(ds::WIDTH as i32)).desc("Image width [px], 1-4096"),
    HEIGHT = Var::param("height", Start::Int32(ds::HEIGHT as i32)).desc("Image height [px], 1-4096"),
    FOV_H = Var::param("fov_horizontal", Start::Float64(ds::FOV_H_DEG)).unit("deg").range(0.0, 170.0)
        .desc("Horizontal field of view (D435i depth: 87 deg); fx = width/2 / tan(fov/2); 0 = square pixels (fx = fy)"),
    FOV_V = Var::param("fov_vertical", Start::Float64(ds::FOV_V_DEG)).unit("deg").range(1.0, 170.0)
        .desc("Vertical field of view (D435i depth: 58 deg); fy = height/2 / tan(fov/2)"),
    RANGE_MIN = Var::param("range_min", Start::Float64(ds::RANGE_MIN)).unit("m").range(0.0, 1000.0)
        .desc("Near clip of depth (z); nearer pixels are 0 (no data)"),
    RANGE_MAX = Var::param("range_max", Start::Float64(ds::RANGE_MAX)).unit("m").range(0.01, 1000.0)
        .desc("Far clip of depth (z); farther pixels are 0 (no data)"),
    DEPTH_NOISE_MODEL = Var::param("depth_noise_model", Start::Int32(2))
        .desc("0 none; 1 fixed Gaussian depth_noise_sigma (the paper); 2 stereo: RMS = z^2 subpixel / (fx baseline) (Intel)"),
    DEPTH_NOISE_SIGMA = Var::param("depth_noise_sigma", Start::Float64(ds::FIXED_SIGMA)).unit("m").range(0.0, 10.0)
        .desc("Depth noise of model 1, 1 sigma (paper: 0.015 m)"),
    BASELINE = Var::param("baseline", Start::Float64(ds::BASELINE)).unit("m").range(0.001, 10.0)
        .desc("Stereo baseline of model 2 and of the left invalid band (D435i: 50 mm)"),
    SUBPIXEL = Var::param("subpixel", Start::Float64(ds::SUBPIXEL)).range(0.0, 10.0)
        .desc("Sub-pixel disparity RMS of model 2 [px] (Intel: 0.08 typical)"),
    INVALID_BAND = Var::param("invalid_band", Start::Boolean(true))
        .desc("Left-edge invalid band of a left-referenced stereo pair: pixel u is 0 when u < fx baseline / z"),
    EDGE_RATIO = Var::param("depth_edge_ratio", Start::Float64(0.05)).range(0.0, 100.0)
        .desc("Depth discontinuities: a pixel whose 4-neighbour is nearer by more than this fraction of its depth is 0; 0 = off"),
    SUN_AZIMUTH = Var::param("sun_azimuth", Start::Float64(135.0)).unit("deg")
        .desc("Without environment: direction toward the sun in the map frame, counter-clockwise from +x"),
    SUN_ELEVATION = Var::param("sun_elevation", Start::Float64(50.0)).unit("deg").range(-90.0, 90.0)
        .desc("Without environment: sun elevation above the horizon (<= 0: no direct light)"),
    AMBIENT = Var::param("ambient", Start::Float64(0.35)).range(0.0, 10.0)
        .desc("Without environment: diffuse (sky) light relative to direct sunlight on a surface facing the sun"),
    LABELS = Var::param("publish_labels", Start::Boolean(true))
        .desc("Publish the instance-label image (32SC1: scene object id + 1, 0 = nothing)"),
    FRAME_ID = Var::param("frame_id", Start::String("camera_color_optical_frame"))
        .desc("header.frame_id of images and CameraInfo, child of link_frame in TF (optical convention: z forward, x right, y down)"),
    PORT_WINDOW = agrisim_fmi::port_window(),
  },
  ports: {
    // --- outputs ---
    // Frames come with the steps; initialization only sets the sun and visibility outputs.
    IMAGE = Var::output_discrete("image", Start::Binary(&[])).mime(IMAGE_MIME).max_size(agrisim_fmi::port::frames_max_size(image_max_size(3), 2)).init_depends_on(&[])
        .desc("Colour images of the last port_window, sensor_msgs/Image rgb8 (CDR frames)"),
    IMAGE_SEQ = Var::output_discrete("image_seq", Start::Int64(0)).init_depends_on(&[]).desc("Sequence counter of image"),
    DEPTH = Var::output_discrete("depth", Start::Binary(&[])).mime(IMAGE_MIME).max_size(agrisim_fmi::port::frames_max_size(image_max_size(4), 2)).init_depends_on(&[])
        .desc("Depth images of the last port_window (CDR frames) aligned to the colour image, sensor_msgs/Image 32FC1, z in metres, 0 = no data (REP 118)"),
    DEPTH_SEQ = Var::output_discrete("depth_seq", Start::Int64(0)).init_depends_on(&[]).desc("Sequence counter of depth"),
    CAMERA_INFO = Var::output_discrete("camera_info", Start::Binary(&[])).mime(CAMERA_INFO_MIME).max_size(agrisim_fmi::port::frames_max_size(HEADER_ROOM, 1024))
        .init_depends_on(&[])
        .desc("Calibration of each frame (CDR frames): plumb_bob, zero distortion, K from the field of view"),
    CAMERA_INFO_SEQ = Var::output_discrete("camera_info_seq", Start::Int64(0)).init_depends_on(&[])
        .desc("Sequence counter of camera_info"),
    LABELS_IMAGE = Var::output_discrete("labels", Start::Binary(&[])).mime(IMAGE_MIME).max_size(agrisim_fmi::port::frames_max_size(image_max_size(4), 2))
        .init_depends_on(&[])
        .desc("Instance labels of each frame (CDR frames), sensor_msgs/Image 32SC1: scene object id + 1 per pixel, 0 = nothing (empty when publish_labels is false)"),
    LABELS_SEQ = Var::output_discrete("labels_seq", Start::Int64(0)).init_depends_on(&[]).desc("Sequence counter of labels"),
    SOLAR_ZENITH = Var::output_discrete("solar_zenith", Start::Float64(0.0)).unit("deg").init_depends_on(&[ENVIRONMENT, SUN_ELEVATION])
        .desc("With environment: the sun's topocentric zenith angle with refraction (NREL SPA); else 90 - sun_elevation"),
    SOLAR_AZIMUTH = Var::output_discrete("solar_azimuth", Start::Float64(0.0)).unit("deg").init_depends_on(&[ENVIRONMENT, SUN_AZIMUTH])
        .desc("With environment: the sun's compass azimuth, clockwise from north (NREL SPA); else the map angle sun_azimuth"),
    VISIBILITY = Var::output_discrete("visibility", Start::Float64(0.0)).unit("m").init_depends_on(&[ENVIRONMENT])
        .desc("Meteorological visibility of the environment (Koschmieder, 3.912 / extinction); 0 = no environment (clear air)"),
    TF_STATIC = Var::output_discrete("tf_static", Start::Binary(&[])).mime(TF_MIME).max_size(agrisim_fmi::port::frames_max_size(HEADER_ROOM, 2))
        .init_depends_on(&[])
        .desc("The camera's fixed frames, once, at the first step (CDR frames), tf2_msgs/TFMessage: mount_parent -> link_frame (the mount) and link_frame -> frame_id (the optical axes); wired to /tf_static, they hang the camera on the robot's TF tree as robot_state_publisher publishes it"),
    TF_STATIC_SEQ = Var::output_discrete("tf_static_seq", Start::Int64(0)).init_depends_on(&[]).desc("Sequence counter of tf_static"),
    VALID_DEPTH = Var::output_discrete("valid_depth_pixels", Start::Int32(0)).init_depends_on(&[])
        .desc("Pixels with depth data in the latest frame"),
  },
}}
