//! The Camera FMU, driven as any FMI importer would: one instance per frame (its `scene` and
//! `environment` are parameters, fixed at initialization), stepped until its first frame is
//! out, and the four message ports read.

use agrisim_cosim::archive::FmuArchive;
use agrisim_cosim::fmi3::Instance;
use agrisim_cosim::model_description::ModelVariable;
use agrisim_cosim::value::{self, Value};
use agrisim_error::Result;
use agrisim_msgs::sensor_msgs::{CameraInfo, Image};
use agrisim_msgs::Message;
use std::path::Path;

const STEP: f64 = 0.02;

pub struct CameraFmu {
    archive: FmuArchive,
    /// An instance kept for the whole run: while it lives the library stays loaded, and with
    /// it the FMU's cache of the last scene (a scene is built once, not once per frame).
    _keeper: Instance,
}

/// One frame and what the camera reported with it.
pub struct Shot {
    pub rgb: Image,
    pub depth: Image,
    pub labels: Image,
    pub info: CameraInfo,
    /// The sun's topocentric zenith and compass azimuth [deg], visibility [m] (0 = clear air).
    pub solar_zenith: f64,
    pub solar_azimuth: f64,
    pub visibility: f64,
    pub range_max: f64,
}

impl CameraFmu {
    pub fn open(fmu_dir: &Path, cache_dir: &Path) -> Result<CameraFmu> {
        let archive = FmuArchive::open(&fmu_dir.join("Camera.fmu"), cache_dir)?;
        let keeper = Instance::instantiate(&archive, "camera_keeper", false)?;
        Ok(CameraFmu { archive, _keeper: keeper })
    }

    pub fn variable(&self, name: &str) -> Result<ModelVariable> {
        self.archive
            .md
            .variable(name)
            .cloned()
            .ok_or_else(|| agrisim_error::err!("Camera.fmu has no variable '{name}'"))
    }

    fn get(&self, inst: &mut Instance, name: &str) -> Result<Value> {
        value::get(inst, &self.variable(name)?)
    }

    fn get_f64(&self, inst: &mut Instance, name: &str) -> Result<f64> {
        match self.get(inst, name)? {
            Value::F64(v) => Ok(v),
            other => Err(agrisim_error::err!("Camera {name} is {other:?}, expected Float64")),
        }
    }

    /// The newest message of port `name`, once its sequence counter has moved.
    fn latest(&self, inst: &mut Instance, name: &str) -> Result<Vec<u8>> {
        match self.get(inst, name)? {
            Value::Bin(b) => {
                let frames = agrisim_frames::decode(&b).map_err(|e| agrisim_error::err!("Camera {name}: {e}"))?;
                frames
                    .last()
                    .map(|f| f.payload.to_vec())
                    .ok_or_else(|| agrisim_error::err!("Camera: no message in {name}"))
            }
            other => Err(agrisim_error::err!("Camera {name} is {other:?}, expected Binary")),
        }
    }

    /// Instantiates with `values` (parameters and inputs, in order), initializes and steps
    /// until the labels port has a frame (the last port a frame publishes).
    pub fn shoot(&self, values: &[(String, Value)]) -> Result<Shot> {
        let mut inst = Instance::instantiate(&self.archive, "camera", false)?;
        for (name, v) in values {
            value::set(&mut inst, &self.variable(name)?, v)?;
        }
        inst.enter_initialization_mode(0.0, None)?;
        inst.exit_initialization_mode()?;
        let mut t = 0.0;
        while !matches!(self.get(&mut inst, "labels_seq")?, Value::I64(n) if n > 0) {
            if t > 1.0 {
                return Err(agrisim_error::err!("Camera: no frame within 1 s (publish_labels off?)"));
            }
            inst.do_step(t, STEP)?;
            t += STEP;
        }
        let image = |name: &str, inst: &mut Instance| -> Result<Image> {
            Image::from_cdr(&self.latest(inst, name)?).map_err(|e| agrisim_error::err!("Camera {name}: {e}"))
        };
        let rgb = image("image", &mut inst)?;
        let depth = image("depth", &mut inst)?;
        let labels = image("labels", &mut inst)?;
        let info = CameraInfo::from_cdr(&self.latest(&mut inst, "camera_info")?)
            .map_err(|e| agrisim_error::err!("Camera camera_info: {e}"))?;
        for (im, encoding, bytes) in [(&rgb, "rgb8", 3), (&depth, "32FC1", 4), (&labels, "32SC1", 4)] {
            let n = im.width as usize * im.height as usize;
            if im.encoding != encoding
                || im.data.len() != n * bytes
                || (im.width, im.height) != (info.width, info.height)
            {
                return Err(agrisim_error::err!(
                    "Camera: {} image {}x{} of {} bytes, expected {encoding} {}x{}",
                    im.encoding,
                    im.width,
                    im.height,
                    im.data.len(),
                    info.width,
                    info.height
                ));
            }
        }
        Ok(Shot {
            solar_zenith: self.get_f64(&mut inst, "solar_zenith")?,
            solar_azimuth: self.get_f64(&mut inst, "solar_azimuth")?,
            visibility: self.get_f64(&mut inst, "visibility")?,
            range_max: self.get_f64(&mut inst, "range_max")?,
            rgb,
            depth,
            labels,
            info,
        })
    }
}
