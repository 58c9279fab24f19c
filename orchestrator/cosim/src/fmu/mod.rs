//! [`FmuInstance`]: what the master asks of one FMU instance, whatever its FMI version and
//! interface. FMI 3 and FMI 2 co-simulation instances implement it directly; a
//! model-exchange instance is wrapped in the master's fixed-step integrator
//! ([`crate::me::Integrated`]), which steps it like a co-simulation FMU.
//!
//! Errors are [`FmiError`]s naming the instance, model, FMI function and variables, the same
//! for both versions. What a version lacks (Int64 and Binary in FMI 2) is refused up front
//! without calling the FMU.

pub(crate) mod core;
pub(crate) mod error;
pub(crate) mod library;
pub(crate) mod log;
mod status;

use crate::model_description::{FmiVersion, Interface};
pub use error::{FmiError, FmiErrorInfo};
pub use log::LogMessage;
pub use status::{Status, StepResult};

/// Where the instance is in the FMI state machine, as far as the wrapper knows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum InstanceState {
    Instantiated,
    InitializationMode,
    StepMode,
    Terminated,
    /// The last call returned fmi3Error: only `reset`, restoring an FMU state (or dropping)
    /// makes sense now. (fmi3Discard does not lead here.)
    Error,
    /// The FMU returned fmi3Fatal: every further call is refused, and it is never freed.
    Fatal,
}

/// A value reference.
pub type Vr = u32;

/// A saved FMU state. Owned by the instance that made it, which frees any states still held
/// when it is dropped; only valid with that instance.
#[derive(Debug)]
pub struct FmuState {
    pub(crate) slot: usize,
    pub(crate) owner: u64,
}

/// One live FMU instance behind a version-independent API (see the module doc).
pub trait FmuInstance: Send {
    fn name(&self) -> &str;
    fn model_name(&self) -> &str;
    fn fmi_version(&self) -> FmiVersion;
    fn interface(&self) -> Interface;
    /// Where the instance is in the FMI state machine, as far as the wrapper knows.
    fn state(&self) -> InstanceState;
    /// Messages logged since the last call, oldest first (bounded).
    fn take_log(&mut self) -> Vec<LogMessage>;
    /// Messages received since instantiation.
    fn log_count(&self) -> u64;
    fn set_debug_logging(&mut self, on: bool, categories: &[&str]) -> Result<(), FmiError>;
    fn enter_initialization_mode(&mut self, start_time: f64, stop_time: Option<f64>) -> Result<(), FmiError>;
    fn exit_initialization_mode(&mut self) -> Result<(), FmiError>;
    /// Advances from `t` to `t + h`.
    fn do_step(&mut self, t: f64, h: f64) -> Result<StepResult, FmiError>;
    fn terminate(&mut self) -> Result<(), FmiError>;
    fn reset(&mut self) -> Result<(), FmiError>;
    fn set_f64(&mut self, vrs: &[Vr], values: &[f64]) -> Result<(), FmiError>;
    fn get_f64(&mut self, vrs: &[Vr], values: &mut [f64]) -> Result<(), FmiError>;
    fn set_i32(&mut self, vrs: &[Vr], values: &[i32]) -> Result<(), FmiError>;
    fn get_i32(&mut self, vrs: &[Vr], values: &mut [i32]) -> Result<(), FmiError>;
    fn set_i64(&mut self, vrs: &[Vr], values: &[i64]) -> Result<(), FmiError>;
    fn get_i64(&mut self, vrs: &[Vr], values: &mut [i64]) -> Result<(), FmiError>;
    fn set_bool(&mut self, vrs: &[Vr], values: &[bool]) -> Result<(), FmiError>;
    fn get_bool(&mut self, vrs: &[Vr], values: &mut [bool]) -> Result<(), FmiError>;
    fn set_string(&mut self, vr: Vr, value: &str) -> Result<(), FmiError>;
    fn get_string(&mut self, vr: Vr) -> Result<String, FmiError>;
    fn set_binary(&mut self, vr: Vr, value: &[u8]) -> Result<(), FmiError>;
    /// The bytes in FMU-owned memory, valid until the FMU's next call.
    fn get_binary_ref(&mut self, vr: Vr) -> Result<&[u8], FmiError>;
    fn get_binary(&mut self, vr: Vr) -> Result<Vec<u8>, FmiError> {
        Ok(self.get_binary_ref(vr)?.to_vec())
    }
    /// Saves the FMU's state (needs canGetAndSetFMUState).
    fn get_state(&mut self) -> Result<FmuState, FmiError>;
    /// Restores a state saved by this instance, with the state-machine state it was saved in.
    fn set_state(&mut self, state: &FmuState) -> Result<(), FmiError>;
    /// The bytes of a saved state (needs canSerializeFMUState) and the state it was saved in.
    fn serialize_state(&mut self, state: &FmuState) -> Result<(Vec<u8>, InstanceState), FmiError>;
    /// A new saved state from bytes of [`FmuInstance::serialize_state`].
    fn deserialize_state(&mut self, bytes: &[u8], saved_in: InstanceState) -> Result<FmuState, FmiError>;
    /// Frees a saved state now (otherwise it is freed with the instance).
    fn free_state(&mut self, state: FmuState) -> Result<(), FmiError>;
}

/// Implements [`FmuInstance`] for a type whose inherent methods have the trait's names
/// (the FMI 3 and FMI 2 instances), version and interface aside.
macro_rules! delegate_fmu_instance {
    ($t:ty) => {
        impl $crate::fmu::FmuInstance for $t {
            fn name(&self) -> &str {
                <$t>::name(self)
            }
            fn model_name(&self) -> &str {
                <$t>::model_name(self)
            }
            fn fmi_version(&self) -> $crate::model_description::FmiVersion {
                <$t>::fmi_version(self)
            }
            fn interface(&self) -> $crate::model_description::Interface {
                <$t>::interface(self)
            }
            fn state(&self) -> $crate::fmu::InstanceState {
                <$t>::state(self)
            }
            fn take_log(&mut self) -> Vec<$crate::fmu::LogMessage> {
                <$t>::take_log(self)
            }
            fn log_count(&self) -> u64 {
                <$t>::log_count(self)
            }
            fn set_debug_logging(&mut self, on: bool, categories: &[&str]) -> Result<(), $crate::fmu::FmiError> {
                <$t>::set_debug_logging(self, on, categories)
            }
            fn enter_initialization_mode(
                &mut self,
                start_time: f64,
                stop_time: Option<f64>,
            ) -> Result<(), $crate::fmu::FmiError> {
                <$t>::enter_initialization_mode(self, start_time, stop_time)
            }
            fn exit_initialization_mode(&mut self) -> Result<(), $crate::fmu::FmiError> {
                <$t>::exit_initialization_mode(self)
            }
            fn do_step(&mut self, t: f64, h: f64) -> Result<$crate::fmu::StepResult, $crate::fmu::FmiError> {
                <$t>::do_step(self, t, h)
            }
            fn terminate(&mut self) -> Result<(), $crate::fmu::FmiError> {
                <$t>::terminate(self)
            }
            fn reset(&mut self) -> Result<(), $crate::fmu::FmiError> {
                <$t>::reset(self)
            }
            fn set_f64(&mut self, vrs: &[u32], values: &[f64]) -> Result<(), $crate::fmu::FmiError> {
                <$t>::set_f64(self, vrs, values)
            }
            fn get_f64(&mut self, vrs: &[u32], values: &mut [f64]) -> Result<(), $crate::fmu::FmiError> {
                <$t>::get_f64(self, vrs, values)
            }
            fn set_i32(&mut self, vrs: &[u32], values: &[i32]) -> Result<(), $crate::fmu::FmiError> {
                <$t>::set_i32(self, vrs, values)
            }
            fn get_i32(&mut self, vrs: &[u32], values: &mut [i32]) -> Result<(), $crate::fmu::FmiError> {
                <$t>::get_i32(self, vrs, values)
            }
            fn set_i64(&mut self, vrs: &[u32], values: &[i64]) -> Result<(), $crate::fmu::FmiError> {
                <$t>::set_i64(self, vrs, values)
            }
            fn get_i64(&mut self, vrs: &[u32], values: &mut [i64]) -> Result<(), $crate::fmu::FmiError> {
                <$t>::get_i64(self, vrs, values)
            }
            fn set_bool(&mut self, vrs: &[u32], values: &[bool]) -> Result<(), $crate::fmu::FmiError> {
                <$t>::set_bool(self, vrs, values)
            }
            fn get_bool(&mut self, vrs: &[u32], values: &mut [bool]) -> Result<(), $crate::fmu::FmiError> {
                <$t>::get_bool(self, vrs, values)
            }
            fn set_string(&mut self, vr: u32, value: &str) -> Result<(), $crate::fmu::FmiError> {
                <$t>::set_string(self, vr, value)
            }
            fn get_string(&mut self, vr: u32) -> Result<String, $crate::fmu::FmiError> {
                <$t>::get_string(self, vr)
            }
            fn set_binary(&mut self, vr: u32, value: &[u8]) -> Result<(), $crate::fmu::FmiError> {
                <$t>::set_binary(self, vr, value)
            }
            fn get_binary_ref(&mut self, vr: u32) -> Result<&[u8], $crate::fmu::FmiError> {
                <$t>::get_binary_ref(self, vr)
            }
            fn get_state(&mut self) -> Result<$crate::fmu::FmuState, $crate::fmu::FmiError> {
                <$t>::get_state(self)
            }
            fn set_state(&mut self, state: &$crate::fmu::FmuState) -> Result<(), $crate::fmu::FmiError> {
                <$t>::set_state(self, state)
            }
            fn serialize_state(
                &mut self,
                state: &$crate::fmu::FmuState,
            ) -> Result<(Vec<u8>, $crate::fmu::InstanceState), $crate::fmu::FmiError> {
                <$t>::serialize_state(self, state)
            }
            fn deserialize_state(
                &mut self,
                bytes: &[u8],
                saved_in: $crate::fmu::InstanceState,
            ) -> Result<$crate::fmu::FmuState, $crate::fmu::FmiError> {
                <$t>::deserialize_state(self, bytes, saved_in)
            }
            fn free_state(&mut self, state: $crate::fmu::FmuState) -> Result<(), $crate::fmu::FmiError> {
                <$t>::free_state(self, state)
            }
        }
    };
}
pub(crate) use delegate_fmu_instance;
