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

/// Model exchange (FMI 3.0 section 3.2, FMI 2.0 section 3.2.3), for models with continuous
/// states; Step Mode never occurs, Event and Continuous-Time Mode do.
pub(crate) mod me {
    use agrisim_fmi::state::{Mask, CONTINUOUS_TIME, ERROR, EVENT, INITIALIZATION, INSTANTIATED, TERMINATED};
    pub const ALIVE: Mask = INSTANTIATED | INITIALIZATION | EVENT | CONTINUOUS_TIME | TERMINATED;
    pub const RUNNING: Mask = EVENT | CONTINUOUS_TIME;
    pub const TERMINATE: Mask = RUNNING;
    pub const RESET: Mask = ALIVE | ERROR;
    pub const ENTER_INITIALIZATION_MODE: Mask = INSTANTIATED;
    pub const EXIT_INITIALIZATION_MODE: Mask = INITIALIZATION;
    pub const SET_TIME: Mask = RUNNING;
    pub const SET_CONTINUOUS_STATES: Mask = CONTINUOUS_TIME;
    pub const ENTER_CONTINUOUS_TIME_MODE: Mask = EVENT;
    pub const COMPLETED_INTEGRATOR_STEP: Mask = CONTINUOUS_TIME;
    pub const UPDATE_DISCRETE_STATES: Mask = EVENT;
    pub const ENTER_EVENT_MODE_3: Mask = CONTINUOUS_TIME;
    pub const ENTER_EVENT_MODE_2: Mask = RUNNING;
    pub const GET_CONTINUOUS_3: Mask = INITIALIZATION | RUNNING | TERMINATED;
    pub const GET_CONTINUOUS_2: Mask = GET_CONTINUOUS_3 | ERROR;
    pub const GET_NOMINALS_3: Mask = INSTANTIATED | GET_CONTINUOUS_3;
    pub const GET_NOMINALS_2: Mask = INSTANTIATED | GET_CONTINUOUS_2;
    pub const GET_NUMBER_OF: Mask = ALIVE;
    pub const GET_3: Mask = INITIALIZATION | RUNNING | TERMINATED;
    pub const GET_2: Mask = GET_3 | ERROR;
    pub const GET_FMU_STATE_3: Mask = ALIVE;
    pub const GET_FMU_STATE_2: Mask = ALIVE | ERROR;
    pub const SET_FMU_STATE: Mask = ALIVE | ERROR;
    /// DoStep: co-simulation only, never allowed.
    pub const DO_STEP: Mask = 0;
}
