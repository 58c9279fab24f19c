//! Helpers shared by the test files: a capturing logger and instantiation shortcuts.
#![allow(dead_code, clippy::missing_safety_doc, clippy::new_without_default)]

use std::ffi::{c_char, c_void, CStr, CString};

use agrisim_fmi::{fmi3, Model, Status};
use agrisim_fmu_testmodel::TestModel;

pub type Logs = Vec<(Status, String)>;

pub unsafe extern "C" fn capture(env: *mut c_void, status: Status, _cat: *const c_char, msg: *const c_char) {
    (*(env as *mut Logs)).push((status, CStr::from_ptr(msg).to_string_lossy().into_owned()));
}

/// A live FMI 3 instance with its captured logs (boxed so the env pointer stays valid).
pub struct I3 {
    pub p: *mut c_void,
    pub logs: Box<Logs>,
}

impl I3 {
    pub fn new() -> I3 {
        let mut logs: Box<Logs> = Box::default();
        let token = CString::new(TestModel::TOKEN).unwrap();
        let env = (&mut *logs as *mut Logs).cast();
        let p = unsafe {
            fmi3::instantiate_co_simulation::<TestModel>(
                c"t".as_ptr(),
                token.as_ptr(),
                std::ptr::null(),
                0,
                0,
                0,
                0,
                std::ptr::null(),
                0,
                env,
                Some(capture),
                None,
            )
        };
        assert!(!p.is_null());
        I3 { p, logs }
    }
    /// Instantiated -> Step Mode at t = 0.
    pub fn stepping() -> I3 {
        let i = I3::new();
        assert_eq!(unsafe { fmi3::enter_initialization_mode::<TestModel>(i.p, 0, 0.0, 0.0, 0, 0.0) }, Status::Ok);
        assert_eq!(unsafe { fmi3::exit_initialization_mode::<TestModel>(i.p) }, Status::Ok);
        i
    }
    pub fn f64(&self, vr: u32) -> (Status, f64) {
        let mut v = f64::NAN;
        let s = unsafe { fmi3::get_float64::<TestModel>(self.p, &vr, 1, &mut v, 1) };
        (s, v)
    }
    pub fn set_f64(&self, vr: u32, v: f64) -> Status {
        unsafe { fmi3::set_float64::<TestModel>(self.p, &vr, 1, &v, 1) }
    }
    pub fn set_i32(&self, vr: u32, v: i32) -> Status {
        unsafe { fmi3::set_int32::<TestModel>(self.p, &vr, 1, &v, 1) }
    }
    pub fn step(&self, tc: f64, h: f64) -> Status {
        let (mut a, mut b, mut c, mut last) = (0u8, 0u8, 0u8, 0.0);
        unsafe { fmi3::do_step::<TestModel>(self.p, tc, h, 0, &mut a, &mut b, &mut c, &mut last) }
    }
    /// The last error message, which must exist.
    pub fn last_error(&self) -> &str {
        &self.logs.iter().rev().find(|(s, _)| *s >= Status::Error).expect("an error was logged").1
    }
}

impl Drop for I3 {
    fn drop(&mut self) {
        unsafe { fmi3::free_instance::<TestModel>(self.p) }
    }
}

/// vr of a variable by its index constant.
pub fn vr(index: usize) -> u32 {
    index as u32 + 1
}
