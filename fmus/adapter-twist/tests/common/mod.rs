//! A live FMI 3 instance of any model, driven through the generic API layer
//! (`agrisim_fmi::fmi3`), with its log messages captured.
#![allow(dead_code)]

use std::ffi::{c_char, c_void, CStr, CString};
use std::marker::PhantomData;

use agrisim_fmi::{fmi3, Model, Status};

pub type Logs = Vec<(Status, String)>;

unsafe extern "C" fn capture(env: *mut c_void, status: Status, _cat: *const c_char, msg: *const c_char) {
    (*(env as *mut Logs)).push((status, CStr::from_ptr(msg).to_string_lossy().into_owned()));
}

/// vr of a variable by its index in the table.
pub fn vr(index: usize) -> u32 {
    index as u32 + 1
}

/// An instance of `M` (boxed logs, so the environment pointer stays valid).
pub struct Fmu<M: Model> {
    p: *mut c_void,
    pub logs: Box<Logs>,
    _m: PhantomData<M>,
}

impl<M: Model> Fmu<M> {
    pub fn new() -> Self {
        let mut logs: Box<Logs> = Box::default();
        let token = CString::new(M::TOKEN).unwrap();
        let env = (&mut *logs as *mut Logs).cast();
        let p = unsafe {
            fmi3::instantiate_co_simulation::<M>(
                c"adapter".as_ptr(),
                token.as_ptr(),
                std::ptr::null(),
                0,
                1,
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
        Fmu { p, logs, _m: PhantomData }
    }
    pub fn enter_init(&self) {
        assert_eq!(unsafe { fmi3::enter_initialization_mode::<M>(self.p, 0, 0.0, 0.0, 0, 0.0) }, Status::Ok);
    }
    pub fn exit_init(&self) {
        assert_eq!(unsafe { fmi3::exit_initialization_mode::<M>(self.p) }, Status::Ok, "{:?}", self.logs);
    }
    pub fn step(&self, tc: f64, h: f64) -> Status {
        let (mut a, mut b, mut c, mut last) = (0u8, 0u8, 0u8, 0.0);
        unsafe { fmi3::do_step::<M>(self.p, tc, h, 0, &mut a, &mut b, &mut c, &mut last) }
    }
    pub fn set_f64(&self, i: usize, v: f64) {
        assert_eq!(unsafe { fmi3::set_float64::<M>(self.p, &vr(i), 1, &v, 1) }, Status::Ok, "{:?}", self.logs);
    }
    pub fn set_i32(&self, i: usize, v: i32) {
        assert_eq!(unsafe { fmi3::set_int32::<M>(self.p, &vr(i), 1, &v, 1) }, Status::Ok, "{:?}", self.logs);
    }
    pub fn set_i64(&self, i: usize, v: i64) {
        assert_eq!(unsafe { fmi3::set_int64::<M>(self.p, &vr(i), 1, &v, 1) }, Status::Ok, "{:?}", self.logs);
    }
    pub fn set_bool(&self, i: usize, v: bool) {
        let b = v as u8;
        assert_eq!(unsafe { fmi3::set_boolean::<M>(self.p, &vr(i), 1, &b, 1) }, Status::Ok, "{:?}", self.logs);
    }
    pub fn set_string(&self, i: usize, v: &str) {
        let s = CString::new(v).unwrap();
        let p = s.as_ptr();
        assert_eq!(unsafe { fmi3::set_string::<M>(self.p, &vr(i), 1, &p, 1) }, Status::Ok, "{:?}", self.logs);
    }
    pub fn set_binary(&self, i: usize, bytes: &[u8]) {
        let (size, ptr) = (bytes.len(), bytes.as_ptr());
        assert_eq!(unsafe { fmi3::set_binary::<M>(self.p, &vr(i), 1, &size, &ptr, 1) }, Status::Ok, "{:?}", self.logs);
    }
    pub fn f64(&self, i: usize) -> f64 {
        let mut v = f64::NAN;
        assert_eq!(unsafe { fmi3::get_float64::<M>(self.p, &vr(i), 1, &mut v, 1) }, Status::Ok);
        v
    }
    pub fn i32(&self, i: usize) -> i32 {
        let mut v = 0;
        assert_eq!(unsafe { fmi3::get_int32::<M>(self.p, &vr(i), 1, &mut v, 1) }, Status::Ok);
        v
    }
    pub fn i64(&self, i: usize) -> i64 {
        let mut v = 0;
        assert_eq!(unsafe { fmi3::get_int64::<M>(self.p, &vr(i), 1, &mut v, 1) }, Status::Ok);
        v
    }
    pub fn bool(&self, i: usize) -> bool {
        let mut v = 0u8;
        assert_eq!(unsafe { fmi3::get_boolean::<M>(self.p, &vr(i), 1, &mut v, 1) }, Status::Ok);
        v != 0
    }
    pub fn binary(&self, i: usize) -> Vec<u8> {
        let (mut size, mut data) = (0usize, std::ptr::null::<u8>());
        assert_eq!(unsafe { fmi3::get_binary::<M>(self.p, &vr(i), 1, &mut size, &mut data, 1) }, Status::Ok);
        unsafe { std::slice::from_raw_parts(data, size) }.to_vec()
    }
    /// Log messages at `status` or worse.
    pub fn logged(&self, status: Status) -> Vec<&str> {
        self.logs.iter().filter(|(s, _)| *s >= status).map(|(_, m)| m.as_str()).collect()
    }
}

impl<M: Model> Drop for Fmu<M> {
    fn drop(&mut self) {
        unsafe { fmi3::free_instance::<M>(self.p) }
    }
}

/// A frame list of `payloads` numbered from `first_seq`, stamped `stamp_ns`.
pub fn frames(first_seq: u64, stamp_ns: i64, payloads: &[Vec<u8>]) -> Vec<u8> {
    let mut out = vec![];
    agrisim_frames::encode_into(
        &mut out,
        payloads.iter().enumerate().map(|(k, p)| agrisim_frames::Frame {
            seq: first_seq + k as u64,
            stamp_ns,
            payload: p,
        }),
    );
    out
}

/// The payloads of an output frame list.
pub fn payloads(bytes: &[u8]) -> Vec<(u64, i64, Vec<u8>)> {
    agrisim_frames::decode(bytes).unwrap().into_iter().map(|f| (f.seq, f.stamp_ns, f.payload.to_vec())).collect()
}
