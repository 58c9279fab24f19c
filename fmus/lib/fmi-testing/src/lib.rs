//! The FMI test harness every FMU crate runs from its tests (a dev-dependency only, so the
//! product crates never link it): variable-table and ModelStructure checks, serialized-state
//! restores, and randomized call sequences.
//!
//! The fuzzers ([`fuzz_fmi3`], [`fuzz_fmi2`]): each case instantiates (sometimes wrongly),
//! then issues random calls into the generic API layer of `agrisim_fmi`: legal and illegal
//! order, NULL and garbage handles and pointers, unknown value references, type mismatches,
//! wrong array sizes, NaN/huge/negative times, FMU-state round trips, unsupported functions.
//! A shadow state machine predicts what must happen. Asserted: no panic escapes, every status
//! is a valid value, illegal calls fail, errors move the instance to Error (where only the
//! allowed calls work), every failure on a live instance is logged with the function's name,
//! time after a step is `tc + h`. Failures panic with the seed, case and call trace.
//!
//! It reads one internal of `agrisim_fmi`, the instance behind a handle
//! (`agrisim_fmi::Instance`, `#[doc(hidden)]`), to compare its mode, time and live FMU
//! states with the shadow's.

mod args;
mod fuzz2;
mod fuzz3;
mod fuzz_me;
mod logs;
mod restore;
mod rng;
mod shadow;
mod spec;
mod states;
mod structure;

pub use fuzz2::fuzz_fmi2;
pub use fuzz3::fuzz_fmi3;
pub use fuzz_me::{fuzz_me2, fuzz_me3};
pub use restore::{assert_state_round_trip, wiggle_inputs};
pub use structure::{assert_initial_dependencies, assert_no_direct_feedthrough, assert_valid_table};

/// For [`fmu_conformance_tests!`], so its users need not name `agrisim_fmi` themselves.
#[doc(hidden)]
pub use agrisim_fmi::Model;

/// The conformance tests of a model-exchange FMU crate (a model with continuous states):
/// its variable table and continuous states make a valid FMU, its initial dependencies hold,
/// and `seeds` x `cases` random FMI 3 and FMI 2 model-exchange call sequences never let a
/// panic escape nor break the state machine. (The co-simulation checks of
/// [`fmu_conformance_tests!`] do not apply: such an FMU cannot be instantiated for
/// co-simulation.)
#[macro_export]
macro_rules! fmu_me_conformance_tests {
    ($model:ty, seeds = $seeds:expr, cases = $cases:expr) => {
        #[test]
        fn variable_table_makes_a_valid_fmu() {
            $crate::assert_valid_table::<$model>();
        }

        #[test]
        fn initial_dependencies_are_complete() {
            $crate::assert_initial_dependencies::<$model>(&[]);
        }

        #[test]
        fn random_fmi3_model_exchange_call_sequences() {
            for seed in 0..$seeds {
                $crate::fuzz_me3::<$model>(seed, $cases);
            }
        }

        #[test]
        fn random_fmi2_model_exchange_call_sequences() {
            for seed in 0..$seeds {
                $crate::fuzz_me2::<$model>(seed, $cases);
            }
        }
    };
}

/// The conformance tests every FMU crate runs, in one line of its `tests/fmi_fuzz.rs`:
/// its variable table makes a valid FMU, its ModelStructure dependencies hold (initial
/// dependencies complete, no direct feedthrough), and `seeds` x `cases` random FMI 3 and
/// FMI 2 call sequences (illegal orders, NULLs, bad value references, wrong sizes, NaN, odd
/// step sizes) never let a panic escape nor return an invalid status.
///
/// ```ignore
/// agrisim_fmi_testing::fmu_conformance_tests!(agrisim_chassis::ChassisKinematic, seeds = 4, cases = 300);
/// ```
#[macro_export]
macro_rules! fmu_conformance_tests {
    ($model:ty, seeds = $seeds:expr, cases = $cases:expr) => {
        #[test]
        fn variable_table_makes_a_valid_fmu() {
            $crate::assert_valid_table::<$model>();
        }

        #[test]
        fn initial_dependencies_are_complete() {
            $crate::assert_initial_dependencies::<$model>(&[]);
        }

        #[test]
        fn no_output_changes_when_inputs_are_set() {
            $crate::assert_no_direct_feedthrough::<$model>();
        }

        #[test]
        fn random_fmi3_call_sequences() {
            for seed in 0..$seeds {
                $crate::fuzz_fmi3::<$model>(seed, $cases);
            }
        }

        #[test]
        fn random_fmi2_call_sequences() {
            for seed in 0..$seeds {
                $crate::fuzz_fmi2::<$model>(seed, $cases);
            }
        }

        #[test]
        fn serialized_states_restore_exactly() {
            let h = <$model as $crate::Model>::STEP_SIZE;
            $crate::assert_state_round_trip::<$model>(&[], h, 13, 12, &$crate::wiggle_inputs::<$model>);
        }
    };
}
