/// The allowed-call tables, written out again on purpose: the harness is an independent
/// oracle and must not share the layer's masks (FMI 3.0 section 4.2 / FMI 2.0 section 4.2.4,
/// co-simulation without event mode; Error = after a call returned Error).
pub(crate) mod fmi3 {
    use agrisim_fmi::state::{Mask, ERROR, INITIALIZATION, INSTANTIATED, STEP, TERMINATED};
    const ALIVE: Mask = INSTANTIATED | INITIALIZATION | STEP | TERMINATED;
    pub const SET_DEBUG_LOGGING: Mask = ALIVE | ERROR;
    pub const ENTER_INITIALIZATION_MODE: Mask = INSTANTIATED;
    pub const EXIT_INITIALIZATION_MODE: Mask = INITIALIZATION;
    pub const TERMINATE: Mask = STEP;
    pub const RESET: Mask = ALIVE | ERROR;
    pub const GET: Mask = INITIALIZATION | STEP | TERMINATED;
    pub const SET: Mask = INSTANTIATED | INITIALIZATION | STEP;
    pub const GET_FMU_STATE: Mask = ALIVE;
    pub const SET_FMU_STATE: Mask = ALIVE | ERROR;
    pub const FREE_FMU_STATE: Mask = ALIVE | ERROR;
    pub const DESERIALIZE_FMU_STATE: Mask = ALIVE | ERROR;
    pub const DO_STEP: Mask = STEP;
}

pub(crate) mod fmi2 {
    use agrisim_fmi::state::{Mask, ERROR, INITIALIZATION, INSTANTIATED, STEP, TERMINATED};
    const ALIVE: Mask = INSTANTIATED | INITIALIZATION | STEP | TERMINATED;
    pub const SET_DEBUG_LOGGING: Mask = ALIVE | ERROR;
    pub const SETUP_EXPERIMENT: Mask = INSTANTIATED;
    pub const ENTER_INITIALIZATION_MODE: Mask = INSTANTIATED;
    pub const EXIT_INITIALIZATION_MODE: Mask = INITIALIZATION;
    pub const TERMINATE: Mask = STEP;
    pub const RESET: Mask = ALIVE | ERROR;
    pub const GET: Mask = INITIALIZATION | STEP | TERMINATED | ERROR;
    pub const SET: Mask = INSTANTIATED | INITIALIZATION | STEP;
    pub const GET_FMU_STATE: Mask = ALIVE | ERROR;
    pub const SET_FMU_STATE: Mask = ALIVE | ERROR;
    pub const FREE_FMU_STATE: Mask = ALIVE | ERROR;
    pub const DESERIALIZE_FMU_STATE: Mask = ALIVE | ERROR;
    pub const DO_STEP: Mask = STEP;
    pub const GET_STATUS: Mask = STEP | TERMINATED | ERROR;
}
