//! The CiA 402 device state machine and the enable handshake, against the IEC 61800-7-201
//! (CiA 402) drive profile's state diagram (transitions 0..16) and command table (0x6040).
//!
//! - A known-answer test for every transition 0..16: start state, controlword (the table's
//!   typical words 0x0006, 0x0007, 0x000F, 0x0000, 0x0002, 0x0080), inputs → transition number,
//!   end state and statusword.
//! - The combinations the diagram has no transition for are ignored.
//! - Properties over random controlwords and inputs (fixed seed): operation enabled is entered
//!   only by transitions 4 and 16; the statusword always decodes to the state; every reported
//!   transition matches the diagram.
//! - The controller's enable handshake against the device: three exchanges to operation
//!   enabled, time-outs naming the step, fault → fault reset → re-enable, loss of enable.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use tandem_motion::plant::cia402::{
    Cia402State, DeviceInputs, DeviceStateMachine, EnableSequence, EnableStatus, EnableStep,
    PowerRequest, QuickStopOption, Transition,
};

use Cia402State as S;

const MS: i64 = 1_000_000;

const NONE: DeviceInputs = DeviceInputs {
    fault: false,
    reaction_finished: false,
    self_test_done: true,
};
const FAULT: DeviceInputs = DeviceInputs {
    fault: true,
    reaction_finished: false,
    self_test_done: true,
};
const FINISHED: DeviceInputs = DeviceInputs {
    fault: false,
    reaction_finished: true,
    self_test_done: true,
};

/// A device in `state`, brought there through the diagram with the typical words; the last
/// controlword it saw is the one that brought it there (never 0x0080).
fn device(option: QuickStopOption, state: Cia402State) -> DeviceStateMachine {
    let mut sm = DeviceStateMachine::new(option);
    let path: &[(u16, DeviceInputs)] = match state {
        S::NotReadyToSwitchOn => &[(0x0000, DeviceInputs::default())],
        S::SwitchOnDisabled => &[(0x0000, NONE), (0x0000, NONE)],
        S::ReadyToSwitchOn => &[(0, NONE), (0, NONE), (0x0006, NONE)],
        S::SwitchedOn => &[(0, NONE), (0, NONE), (0x0006, NONE), (0x0007, NONE)],
        S::OperationEnabled => &[(0, NONE), (0, NONE), (6, NONE), (7, NONE), (0x000F, NONE)],
        S::QuickStopActive => &[
            (0, NONE),
            (0, NONE),
            (6, NONE),
            (7, NONE),
            (0xF, NONE),
            (0x0002, NONE),
        ],
        S::FaultReactionActive => &[(0, NONE), (0, NONE), (0x0000, FAULT)],
        S::Fault => &[(0, NONE), (0, NONE), (0x0000, FAULT), (0x0000, FINISHED)],
    };
    for &(cw, inputs) in path {
        assert!(
            sm.step(cw, inputs).is_some(),
            "path to {state} at {cw:#06x}"
        );
    }
    assert_eq!(sm.state(), state);
    sm
}

/// Steps `sm` once and checks the transition, the end state and the statusword.
#[track_caller]
fn expect(
    sm: &mut DeviceStateMachine,
    cw: u16,
    inputs: DeviceInputs,
    number: u8,
    to: Cia402State,
    sw: u16,
) {
    let from = sm.state();
    let t = sm
        .step(cw, inputs)
        .unwrap_or_else(|| panic!("no transition from {from} on {cw:#06x}"));
    assert_eq!(
        t,
        Transition {
            number,
            from: Some(from),
            to
        },
        "from {from} on {cw:#06x} {inputs:?}"
    );
    assert_eq!(sm.state(), to);
    assert_eq!(sm.statusword(), sw, "statusword of {to}");
    assert_eq!(Cia402State::from_statusword(sw), Some(to));
}

#[track_caller]
fn ignored(sm: &mut DeviceStateMachine, cw: u16, inputs: DeviceInputs) {
    let from = sm.state();
    assert_eq!(
        sm.step(cw, inputs),
        None,
        "{from} must ignore {cw:#06x} {inputs:?}"
    );
    assert_eq!(sm.state(), from);
}

const QS: QuickStopOption = QuickStopOption::QuickStopRamp;
const QS_STAY: QuickStopOption = QuickStopOption::QuickStopRampStay;

#[test]
fn transition_0_power_up() {
    let mut sm = DeviceStateMachine::new(QS);
    assert_eq!(sm.state(), S::NotReadyToSwitchOn);
    let t = sm.step(0x0000, DeviceInputs::default()).unwrap();
    assert_eq!(
        t,
        Transition {
            number: 0,
            from: None,
            to: S::NotReadyToSwitchOn
        }
    );
    assert_eq!(sm.statusword(), 0x0000);
    // Transition 0 happens once.
    ignored(&mut sm, 0x0000, DeviceInputs::default());
}

#[test]
fn transition_1_self_test_done() {
    let mut sm = device(QS, S::NotReadyToSwitchOn);
    // The self test is not done: no command moves the device.
    for cw in [0x0006, 0x0007, 0x000F, 0x0080] {
        ignored(&mut sm, cw, DeviceInputs::default());
    }
    expect(&mut sm, 0x0000, NONE, 1, S::SwitchOnDisabled, 0x0040);
}

#[test]
fn transition_2_shutdown() {
    expect(
        &mut device(QS, S::SwitchOnDisabled),
        0x0006,
        NONE,
        2,
        S::ReadyToSwitchOn,
        0x0031,
    );
}

#[test]
fn transition_3_switch_on() {
    expect(
        &mut device(QS, S::ReadyToSwitchOn),
        0x0007,
        NONE,
        3,
        S::SwitchedOn,
        0x0033,
    );
}

#[test]
fn transition_3_then_4_switch_on_enable_operation() {
    let mut sm = device(QS, S::ReadyToSwitchOn);
    expect(&mut sm, 0x000F, NONE, 3, S::SwitchedOn, 0x0033);
    expect(&mut sm, 0x000F, NONE, 4, S::OperationEnabled, 0x0037);
}

#[test]
fn transition_4_enable_operation() {
    expect(
        &mut device(QS, S::SwitchedOn),
        0x000F,
        NONE,
        4,
        S::OperationEnabled,
        0x0037,
    );
}

#[test]
fn transition_5_disable_operation() {
    expect(
        &mut device(QS, S::OperationEnabled),
        0x0007,
        NONE,
        5,
        S::SwitchedOn,
        0x0033,
    );
}

#[test]
fn transition_6_shutdown_from_switched_on() {
    expect(
        &mut device(QS, S::SwitchedOn),
        0x0006,
        NONE,
        6,
        S::ReadyToSwitchOn,
        0x0031,
    );
}

#[test]
fn transition_7_disable_voltage_or_quick_stop_from_ready() {
    expect(
        &mut device(QS, S::ReadyToSwitchOn),
        0x0000,
        NONE,
        7,
        S::SwitchOnDisabled,
        0x0040,
    );
    expect(
        &mut device(QS, S::ReadyToSwitchOn),
        0x0002,
        NONE,
        7,
        S::SwitchOnDisabled,
        0x0040,
    );
}

#[test]
fn transition_8_shutdown_from_operation_enabled() {
    expect(
        &mut device(QS, S::OperationEnabled),
        0x0006,
        NONE,
        8,
        S::ReadyToSwitchOn,
        0x0031,
    );
}

#[test]
fn transition_9_disable_voltage_from_operation_enabled() {
    expect(
        &mut device(QS, S::OperationEnabled),
        0x0000,
        NONE,
        9,
        S::SwitchOnDisabled,
        0x0040,
    );
}

#[test]
fn transition_10_disable_voltage_or_quick_stop_from_switched_on() {
    expect(
        &mut device(QS, S::SwitchedOn),
        0x0000,
        NONE,
        10,
        S::SwitchOnDisabled,
        0x0040,
    );
    expect(
        &mut device(QS, S::SwitchedOn),
        0x0002,
        NONE,
        10,
        S::SwitchOnDisabled,
        0x0040,
    );
}

#[test]
fn transition_11_quick_stop() {
    for option in 0..=8 {
        let option = QuickStopOption::try_from(option).unwrap();
        expect(
            &mut device(option, S::OperationEnabled),
            0x0002,
            NONE,
            11,
            S::QuickStopActive,
            0x0017,
        );
    }
}

#[test]
fn transition_12_quick_stop_finished_with_options_0_to_4() {
    for option in 1..=4 {
        let option = QuickStopOption::try_from(option).unwrap();
        let mut sm = device(option, S::QuickStopActive);
        // The ramp is running: stay.
        ignored(&mut sm, 0x0002, NONE);
        ignored(&mut sm, 0x000F, NONE);
        expect(&mut sm, 0x0002, FINISHED, 12, S::SwitchOnDisabled, 0x0040);
    }
    // Option 0 disables the drive function at once: nothing to wait for.
    let mut sm = device(QuickStopOption::DisableDrive, S::QuickStopActive);
    expect(&mut sm, 0x0002, NONE, 12, S::SwitchOnDisabled, 0x0040);
}

#[test]
fn transition_12_disable_voltage_in_quick_stop_active() {
    for option in 0..=8 {
        let option = QuickStopOption::try_from(option).unwrap();
        expect(
            &mut device(option, S::QuickStopActive),
            0x0000,
            NONE,
            12,
            S::SwitchOnDisabled,
            0x0040,
        );
    }
}

#[test]
fn options_5_to_8_stay_in_quick_stop_active() {
    for option in 5..=8 {
        let option = QuickStopOption::try_from(option).unwrap();
        let mut sm = device(option, S::QuickStopActive);
        ignored(&mut sm, 0x0002, FINISHED);
        ignored(&mut sm, 0x0006, FINISHED);
        ignored(&mut sm, 0x0007, FINISHED);
        assert_eq!(sm.statusword(), 0x0017);
    }
}

#[test]
fn transition_13_fault_from_any_state() {
    for from in [
        S::NotReadyToSwitchOn,
        S::SwitchOnDisabled,
        S::ReadyToSwitchOn,
        S::SwitchedOn,
        S::OperationEnabled,
        S::QuickStopActive,
    ] {
        for cw in [0x0000, 0x0006, 0x0007, 0x000F, 0x0002, 0x0080] {
            let mut inputs = FAULT;
            inputs.self_test_done = from != S::NotReadyToSwitchOn;
            expect(
                &mut device(QS, from),
                cw,
                inputs,
                13,
                S::FaultReactionActive,
                0x001F,
            );
        }
    }
    // In the fault states a fault cause is no new fault.
    ignored(&mut device(QS, S::FaultReactionActive), 0x0000, FAULT);
    ignored(&mut device(QS, S::Fault), 0x0000, FAULT);
}

#[test]
fn transition_14_fault_reaction_finished() {
    let mut sm = device(QS, S::FaultReactionActive);
    // The reaction runs: no command leaves fault reaction active, not even a fault reset.
    for cw in [0x0080, 0x0000, 0x0006, 0x000F] {
        ignored(&mut sm, cw, NONE);
    }
    // The fault cause may still be present: the reaction still ends.
    let mut inputs = FINISHED;
    inputs.fault = true;
    expect(&mut sm, 0x0000, inputs, 14, S::Fault, 0x0008);
}

#[test]
fn transition_15_fault_reset_edge_once_the_cause_is_gone() {
    let mut sm = device(QS, S::Fault);
    // Edge while the cause is present: refused.
    ignored(&mut sm, 0x0080, FAULT);
    // Bit 7 held while the cause goes: no edge, no reset.
    ignored(&mut sm, 0x0080, NONE);
    ignored(&mut sm, 0x0080, NONE);
    // Dropped, then a new edge: transition 15.
    ignored(&mut sm, 0x0000, NONE);
    expect(&mut sm, 0x0080, NONE, 15, S::SwitchOnDisabled, 0x0040);
    // Bit 7 still set in switch on disabled: nothing.
    ignored(&mut sm, 0x0080, NONE);
    // The next enable goes through shutdown as usual.
    expect(&mut sm, 0x0006, NONE, 2, S::ReadyToSwitchOn, 0x0031);
}

#[test]
fn transition_16_enable_operation_from_quick_stop_active_with_options_5_to_8() {
    for option in 5..=8 {
        let option = QuickStopOption::try_from(option).unwrap();
        expect(
            &mut device(option, S::QuickStopActive),
            0x000F,
            NONE,
            16,
            S::OperationEnabled,
            0x0037,
        );
        // Also after the ramp has finished.
        expect(
            &mut device(option, S::QuickStopActive),
            0x000F,
            FINISHED,
            16,
            S::OperationEnabled,
            0x0037,
        );
    }
    // Options 0..4 have no transition 16.
    for option in 1..=4 {
        let option = QuickStopOption::try_from(option).unwrap();
        ignored(&mut device(option, S::QuickStopActive), 0x000F, NONE);
    }
}

#[test]
fn commands_without_a_transition_are_ignored() {
    let cases: &[(Cia402State, &[u16])] = &[
        (
            S::SwitchOnDisabled,
            &[0x000F, 0x0007, 0x0000, 0x0002, 0x0080, 0x0100],
        ),
        (S::ReadyToSwitchOn, &[0x0006, 0x0080]),
        (S::SwitchedOn, &[0x0007, 0x0080]),
        (S::OperationEnabled, &[0x000F, 0x010F, 0x0080, 0x008F]),
        (S::Fault, &[0x0000, 0x0006, 0x0007, 0x000F, 0x0002]),
    ];
    for &(state, words) in cases {
        for &cw in words {
            ignored(&mut device(QS, state), cw, NONE);
        }
    }
    // Fault reset outside fault does nothing (the other bits are not decoded while bit 7 is
    // set).
    ignored(&mut device(QS, S::OperationEnabled), 0x0080, FINISHED);
}

/// Which transitions may connect which states (the state diagram).
fn diagram(number: u8) -> (&'static [Cia402State], Cia402State) {
    const NON_FAULT: &[Cia402State] = &[
        S::NotReadyToSwitchOn,
        S::SwitchOnDisabled,
        S::ReadyToSwitchOn,
        S::SwitchedOn,
        S::OperationEnabled,
        S::QuickStopActive,
    ];
    match number {
        1 => (&[S::NotReadyToSwitchOn], S::SwitchOnDisabled),
        2 => (&[S::SwitchOnDisabled], S::ReadyToSwitchOn),
        3 => (&[S::ReadyToSwitchOn], S::SwitchedOn),
        4 => (&[S::SwitchedOn], S::OperationEnabled),
        5 => (&[S::OperationEnabled], S::SwitchedOn),
        6 => (&[S::SwitchedOn], S::ReadyToSwitchOn),
        7 => (&[S::ReadyToSwitchOn], S::SwitchOnDisabled),
        8 => (&[S::OperationEnabled], S::ReadyToSwitchOn),
        9 => (&[S::OperationEnabled], S::SwitchOnDisabled),
        10 => (&[S::SwitchedOn], S::SwitchOnDisabled),
        11 => (&[S::OperationEnabled], S::QuickStopActive),
        12 => (&[S::QuickStopActive], S::SwitchOnDisabled),
        13 => (NON_FAULT, S::FaultReactionActive),
        14 => (&[S::FaultReactionActive], S::Fault),
        15 => (&[S::Fault], S::SwitchOnDisabled),
        16 => (&[S::QuickStopActive], S::OperationEnabled),
        n => panic!("transition {n} is not in the diagram"),
    }
}

fn controlword() -> impl Strategy<Value = u16> {
    prop_oneof![
        4 => prop::sample::select(vec![0x0000u16, 0x0002, 0x0006, 0x0007, 0x000F, 0x0080, 0x008F, 0x010F]),
        1 => any::<u16>(),
    ]
}

fn inputs() -> impl Strategy<Value = DeviceInputs> {
    (
        prop::bool::weighted(0.1),
        any::<bool>(),
        prop::bool::weighted(0.8),
    )
        .prop_map(|(fault, reaction_finished, self_test_done)| DeviceInputs {
            fault,
            reaction_finished,
            self_test_done,
        })
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 2000,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(0xC1A4_0201),
        ..ProptestConfig::default()
    })]

    #[test]
    fn device_follows_the_diagram(option in 0i16..=8, steps in prop::collection::vec((controlword(), inputs()), 1..80)) {
        let option = QuickStopOption::try_from(option).unwrap();
        let mut sm = DeviceStateMachine::new(option);
        let mut previous_cw = 0u16;
        for (k, (cw, inputs)) in steps.into_iter().enumerate() {
            let before = sm.state();
            let t = sm.step(cw, inputs);
            match t {
                None => prop_assert_eq!(sm.state(), before),
                Some(t) => {
                    prop_assert_eq!(t.to, sm.state());
                    if k == 0 {
                        prop_assert_eq!(t, Transition { number: 0, from: None, to: S::NotReadyToSwitchOn });
                    } else {
                        prop_assert_eq!(t.from, Some(before));
                        let (from, to) = diagram(t.number);
                        prop_assert!(from.contains(&before), "{} from {}", t.number, before);
                        prop_assert_eq!(to, t.to);
                    }
                    if t.to == S::OperationEnabled {
                        prop_assert!(t.number == 4 || t.number == 16, "entered by {}", t.number);
                    }
                    if t.number == 13 {
                        prop_assert!(inputs.fault);
                    }
                    if t.number == 15 {
                        prop_assert!(!inputs.fault && cw & 0x80 != 0 && previous_cw & 0x80 == 0);
                    }
                    if t.number == 16 {
                        prop_assert!(option.stays_in_quick_stop());
                    }
                }
            }
            prop_assert_eq!(Cia402State::from_statusword(sm.statusword()), Some(sm.state()));
            previous_cw = cw;
        }
    }
}

// ---- The enable handshake against the device ----

fn enable() -> PowerRequest {
    PowerRequest {
        enable: true,
        quick_stop: false,
        fault_reset: false,
    }
}

/// One cycle of controller and device: the controller reads the device's statusword (with the
/// remote bit a real drive sets), the device takes the controlword.
fn exchange(
    seq: &mut EnableSequence,
    sm: &mut DeviceStateMachine,
    now: i64,
    request: PowerRequest,
    inputs: DeviceInputs,
) -> (u16, EnableStatus) {
    let out = seq.step(now, request, sm.statusword() | 0x0200);
    assert_eq!(out.drive_state, Some(sm.state()));
    // Ignoring the transition: the state is checked by the callers.
    let _ = sm.step(out.controlword, inputs);
    (out.controlword, out.status)
}

#[test]
fn enable_takes_three_exchanges_one_per_step() {
    let mut sm = device(QS, S::SwitchOnDisabled);
    let mut seq = EnableSequence::new(100 * MS).unwrap();
    let expected = [
        (0x0006, EnableStep::Shutdown, S::ReadyToSwitchOn),
        (0x0007, EnableStep::SwitchOn, S::SwitchedOn),
        (0x000F, EnableStep::EnableOperation, S::OperationEnabled),
    ];
    for (k, (cw, step, state)) in expected.into_iter().enumerate() {
        let got = exchange(&mut seq, &mut sm, k as i64 * MS, enable(), NONE);
        assert_eq!(got, (cw, EnableStatus::Enabling { step }), "exchange {k}");
        assert_eq!(sm.state(), state, "after exchange {k}");
    }
    for k in 3..10 {
        assert_eq!(
            exchange(&mut seq, &mut sm, k * MS, enable(), NONE),
            (0x000F, EnableStatus::Enabled)
        );
    }
}

#[test]
fn enable_from_power_up_waits_for_the_self_test() {
    let mut sm = DeviceStateMachine::new(QS);
    let mut seq = EnableSequence::new(10 * MS).unwrap();
    // Exchange 0: transition 0; exchange 1: transition 1 (self test); then 2, 3, 4.
    let mut states = Vec::new();
    for k in 0..6 {
        exchange(&mut seq, &mut sm, k * MS, enable(), NONE);
        states.push(sm.state());
    }
    assert_eq!(
        states,
        [
            S::NotReadyToSwitchOn,
            S::SwitchOnDisabled,
            S::ReadyToSwitchOn,
            S::SwitchedOn,
            S::OperationEnabled,
            S::OperationEnabled
        ]
    );
}

#[test]
fn a_drive_stuck_in_switch_on_disabled_times_out_naming_shutdown() {
    let timeout = 50 * MS;
    let t0 = 7 * MS + 123;
    let mut seq = EnableSequence::new(timeout).unwrap();
    let stuck = 0x0250; // switch on disabled, voltage, remote
    let mut k = 0;
    loop {
        let now = t0 + k * MS;
        let out = seq.step(now, enable(), stuck);
        if now - t0 < timeout {
            assert_eq!(
                out.status,
                EnableStatus::Enabling {
                    step: EnableStep::Shutdown
                },
                "at {now}"
            );
            assert_eq!(out.controlword, 0x0006);
        } else {
            assert_eq!(now - t0, timeout, "times out at exactly the timeout");
            assert_eq!(
                out.status,
                EnableStatus::TimedOut {
                    step: EnableStep::Shutdown,
                    state: Some(S::SwitchOnDisabled)
                }
            );
            assert_eq!(out.controlword, 0x0000);
            break;
        }
        k += 1;
    }
    // One nanosecond earlier it had not timed out.
    let mut early = EnableSequence::new(timeout).unwrap();
    early.step(t0, enable(), stuck);
    assert_eq!(
        early.step(t0 + timeout - 1, enable(), stuck).status,
        EnableStatus::Enabling {
            step: EnableStep::Shutdown
        }
    );
    // Latched: the drive is not driven any further until acknowledged.
    let out = seq.step(t0 + 2 * timeout, enable(), stuck);
    assert!(matches!(out.status, EnableStatus::TimedOut { .. }));
    assert_eq!(out.controlword, 0x0000);
    // Acknowledged (MC_Reset): a new attempt with a new timer.
    let ack = PowerRequest {
        fault_reset: true,
        ..enable()
    };
    let t1 = t0 + 3 * timeout;
    let out = seq.step(t1, ack, stuck);
    assert_eq!(
        out.status,
        EnableStatus::Enabling {
            step: EnableStep::Shutdown
        }
    );
    assert_eq!(out.controlword, 0x0006);
    assert_eq!(
        seq.step(t1 + timeout - 1, ack, stuck).status,
        EnableStatus::Enabling {
            step: EnableStep::Shutdown
        }
    );
    assert!(matches!(
        seq.step(t1 + timeout, ack, stuck).status,
        EnableStatus::TimedOut { .. }
    ));
}

#[test]
fn time_outs_name_the_step_and_the_state() {
    let cases = [
        (0x0231u16, EnableStep::SwitchOn, Some(S::ReadyToSwitchOn)),
        (0x0233, EnableStep::EnableOperation, Some(S::SwitchedOn)),
        (
            0x0217,
            EnableStep::EnableOperation,
            Some(S::QuickStopActive),
        ),
        (0x0200, EnableStep::Shutdown, Some(S::NotReadyToSwitchOn)),
        (0x0201, EnableStep::Shutdown, None),
    ];
    for (sw, step, state) in cases {
        let mut seq = EnableSequence::new(5 * MS).unwrap();
        assert_eq!(
            seq.step(0, enable(), sw).status,
            EnableStatus::Enabling { step }
        );
        assert_eq!(
            seq.step(5 * MS, enable(), sw).status,
            EnableStatus::TimedOut { step, state },
            "{sw:#06x}"
        );
    }
    // A step that completes restarts the timer for the next one.
    let mut seq = EnableSequence::new(5 * MS).unwrap();
    seq.step(0, enable(), 0x0250);
    seq.step(4 * MS, enable(), 0x0231);
    assert_eq!(
        seq.step(8 * MS, enable(), 0x0231).status,
        EnableStatus::Enabling {
            step: EnableStep::SwitchOn
        }
    );
    assert_eq!(
        seq.step(9 * MS, enable(), 0x0231).status,
        EnableStatus::TimedOut {
            step: EnableStep::SwitchOn,
            state: Some(S::ReadyToSwitchOn)
        }
    );
}

#[test]
fn fault_then_fault_reset_then_re_enable() {
    let mut sm = device(QS, S::SwitchOnDisabled);
    let mut seq = EnableSequence::new(20 * MS).unwrap();
    let mut now = 0;
    let mut tick = |seq: &mut EnableSequence, sm: &mut DeviceStateMachine, request, inputs| {
        now += MS;
        exchange(seq, sm, now, request, inputs)
    };
    for _ in 0..3 {
        tick(&mut seq, &mut sm, enable(), NONE);
    }
    assert_eq!(
        tick(&mut seq, &mut sm, enable(), NONE),
        (0x000F, EnableStatus::Enabled)
    );
    // A fault cause appears: 13, the handshake reports the fault and stops driving the drive.
    let cause = FAULT;
    tick(&mut seq, &mut sm, enable(), cause);
    assert_eq!(sm.state(), S::FaultReactionActive);
    assert_eq!(
        tick(&mut seq, &mut sm, enable(), cause),
        (0x0000, EnableStatus::Fault)
    );
    // A reset requested during the reaction is held until the drive is in fault.
    let reset = PowerRequest {
        fault_reset: true,
        ..enable()
    };
    let reaction_done_cause_present = DeviceInputs {
        fault: true,
        reaction_finished: true,
        self_test_done: true,
    };
    assert_eq!(
        tick(&mut seq, &mut sm, reset, reaction_done_cause_present),
        (0x0000, EnableStatus::Fault)
    );
    assert_eq!(sm.state(), S::Fault);
    // Now the pulse: bit 7 for exactly one exchange. The cause is still there: refused.
    let waiting = EnableStatus::Enabling {
        step: EnableStep::LeaveFault,
    };
    assert_eq!(tick(&mut seq, &mut sm, reset, cause), (0x0080, waiting));
    assert_eq!(sm.state(), S::Fault);
    let mut words = Vec::new();
    let timed_out = loop {
        let (cw, status) = tick(&mut seq, &mut sm, reset, cause);
        words.push(cw);
        if status != waiting {
            break status;
        }
    };
    assert!(
        words.iter().all(|&w| w == 0x0000),
        "one pulse only: {words:x?}"
    );
    assert_eq!(
        words.len(),
        20,
        "the fault reset step times out after 20 ms"
    );
    assert_eq!(
        timed_out,
        EnableStatus::TimedOut {
            step: EnableStep::LeaveFault,
            state: Some(S::Fault)
        }
    );
    // The cause goes; MC_Reset again (the request falls, then rises).
    assert!(matches!(
        tick(&mut seq, &mut sm, enable(), NONE).1,
        EnableStatus::TimedOut { .. }
    ));
    assert_eq!(tick(&mut seq, &mut sm, reset, NONE), (0x0080, waiting));
    assert_eq!(sm.state(), S::SwitchOnDisabled, "transition 15");
    // Enable is still set: the handshake enables again (S7: MC_Reset re-enables the axis).
    let cws: Vec<u16> = (0..4)
        .map(|_| tick(&mut seq, &mut sm, reset, NONE).0)
        .collect();
    assert_eq!(cws, [0x0006, 0x0007, 0x000F, 0x000F]);
    assert_eq!(sm.state(), S::OperationEnabled);
}

#[test]
fn fault_reset_without_enable_leaves_the_drive_disabled() {
    let mut sm = device(QS, S::Fault);
    let mut seq = EnableSequence::new(20 * MS).unwrap();
    let reset = PowerRequest {
        fault_reset: true,
        ..PowerRequest::default()
    };
    assert_eq!(
        exchange(&mut seq, &mut sm, 0, PowerRequest::default(), NONE),
        (0x0000, EnableStatus::Fault)
    );
    assert_eq!(
        exchange(&mut seq, &mut sm, MS, reset, NONE),
        (0x0080, EnableStatus::Fault)
    );
    assert_eq!(sm.state(), S::SwitchOnDisabled);
    assert_eq!(
        exchange(&mut seq, &mut sm, 2 * MS, reset, NONE),
        (0x0000, EnableStatus::Disabled)
    );
    assert_eq!(sm.state(), S::SwitchOnDisabled);
}

#[test]
fn a_fault_reset_request_outside_fault_sends_no_pulse() {
    let mut sm = device(QS, S::OperationEnabled);
    let mut seq = EnableSequence::new(20 * MS).unwrap();
    let reset = PowerRequest {
        fault_reset: true,
        ..enable()
    };
    assert_eq!(
        exchange(&mut seq, &mut sm, 0, enable(), NONE),
        (0x000F, EnableStatus::Enabled)
    );
    assert_eq!(
        exchange(&mut seq, &mut sm, MS, reset, NONE),
        (0x000F, EnableStatus::Enabled)
    );
    // A fault after the request: no stale reset is sent.
    exchange(&mut seq, &mut sm, 2 * MS, reset, FAULT);
    exchange(&mut seq, &mut sm, 3 * MS, reset, FINISHED);
    assert_eq!(sm.state(), S::Fault);
    for k in 4..10 {
        assert_eq!(
            exchange(&mut seq, &mut sm, k * MS, reset, NONE),
            (0x0000, EnableStatus::Fault)
        );
    }
}

#[test]
fn a_drive_that_drops_out_on_its_own_is_reported_not_re_enabled() {
    let mut sm = device(QS, S::OperationEnabled);
    let mut seq = EnableSequence::new(20 * MS).unwrap();
    assert_eq!(
        exchange(&mut seq, &mut sm, 0, enable(), NONE),
        (0x000F, EnableStatus::Enabled)
    );
    // Safe torque off: the drive goes to switch on disabled by itself (here: transition 9).
    sm.step(0x0000, NONE);
    assert_eq!(sm.state(), S::SwitchOnDisabled);
    let lost = EnableStatus::Lost {
        state: Some(S::SwitchOnDisabled),
    };
    for k in 1..100 {
        assert_eq!(
            exchange(&mut seq, &mut sm, k * MS, enable(), NONE),
            (0x0000, lost)
        );
    }
    assert_eq!(sm.state(), S::SwitchOnDisabled);
    // Acknowledged: enabled again.
    let ack = PowerRequest {
        fault_reset: true,
        ..enable()
    };
    let cws: Vec<u16> = (100..104)
        .map(|k| exchange(&mut seq, &mut sm, k * MS, ack, NONE).0)
        .collect();
    assert_eq!(cws, [0x0006, 0x0007, 0x000F, 0x000F]);
    assert_eq!(sm.state(), S::OperationEnabled);
    // Removing the enable also clears a loss: drop out again, then enable off and on.
    sm.step(0x0007, NONE);
    assert_eq!(sm.state(), S::SwitchedOn);
    assert_eq!(
        exchange(&mut seq, &mut sm, 200 * MS, enable(), NONE).1,
        EnableStatus::Lost {
            state: Some(S::SwitchedOn)
        }
    );
    assert_eq!(
        exchange(&mut seq, &mut sm, 201 * MS, PowerRequest::default(), NONE).1,
        EnableStatus::Disabled
    );
    assert_eq!(
        exchange(&mut seq, &mut sm, 202 * MS, enable(), NONE).1,
        EnableStatus::Enabling {
            step: EnableStep::Shutdown
        }
    );
}

#[test]
fn removing_the_enable_disables_the_drive() {
    let mut sm = device(QS, S::OperationEnabled);
    let mut seq = EnableSequence::new(20 * MS).unwrap();
    exchange(&mut seq, &mut sm, 0, enable(), NONE);
    assert_eq!(
        exchange(&mut seq, &mut sm, MS, PowerRequest::default(), NONE),
        (0x0000, EnableStatus::Disabling)
    );
    assert_eq!(sm.state(), S::SwitchOnDisabled, "transition 9");
    assert_eq!(
        exchange(&mut seq, &mut sm, 2 * MS, PowerRequest::default(), NONE),
        (0x0000, EnableStatus::Disabled)
    );
}

#[test]
fn quick_stop_with_stay_option_then_release_uses_transition_16() {
    let mut sm = device(QS_STAY, S::OperationEnabled);
    let mut seq = EnableSequence::new(20 * MS).unwrap();
    let qs = PowerRequest {
        quick_stop: true,
        ..enable()
    };
    exchange(&mut seq, &mut sm, 0, enable(), NONE);
    assert_eq!(
        exchange(&mut seq, &mut sm, MS, qs, NONE),
        (0x0002, EnableStatus::QuickStopping)
    );
    assert_eq!(sm.state(), S::QuickStopActive);
    assert_eq!(
        exchange(&mut seq, &mut sm, 2 * MS, qs, FINISHED),
        (0x0002, EnableStatus::QuickStopping)
    );
    assert_eq!(sm.state(), S::QuickStopActive, "option 6 stays");
    let out = seq.step(3 * MS, enable(), sm.statusword());
    assert_eq!(out.controlword, 0x000F);
    assert_eq!(sm.step(out.controlword, NONE).map(|t| t.number), Some(16));
    assert_eq!(
        exchange(&mut seq, &mut sm, 4 * MS, enable(), NONE).1,
        EnableStatus::Enabled
    );
}

#[test]
fn quick_stop_with_option_2_ends_disabled_then_re_enables_on_release() {
    let mut sm = device(QS, S::OperationEnabled);
    let mut seq = EnableSequence::new(20 * MS).unwrap();
    let qs = PowerRequest {
        quick_stop: true,
        ..enable()
    };
    exchange(&mut seq, &mut sm, 0, enable(), NONE);
    assert_eq!(
        exchange(&mut seq, &mut sm, MS, qs, NONE),
        (0x0002, EnableStatus::QuickStopping)
    );
    assert_eq!(
        exchange(&mut seq, &mut sm, 2 * MS, qs, FINISHED),
        (0x0002, EnableStatus::QuickStopping)
    );
    assert_eq!(sm.state(), S::SwitchOnDisabled, "transition 12");
    assert_eq!(
        exchange(&mut seq, &mut sm, 3 * MS, qs, NONE),
        (0x0002, EnableStatus::Disabled)
    );
    let cws: Vec<u16> = (4..8)
        .map(|k| exchange(&mut seq, &mut sm, k * MS, enable(), NONE).0)
        .collect();
    assert_eq!(cws, [0x0006, 0x0007, 0x000F, 0x000F]);
}
