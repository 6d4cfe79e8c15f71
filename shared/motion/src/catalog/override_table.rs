//! Override (abort) response of motion-control jobs: which running job a new job aborts.
//!
//! S7-1500T Motion Control V4.0 function manual, chapter 10.16 'Override response of Motion Control
//! jobs V4'. The three tables are stored as **data** ([`TABLE1`], [`TABLE2`], [`TABLE3`]) and read
//! through [`table1`], [`table2`] and [`table3`]. `A` in the manual is [`Effect::Abort`]: the
//! running job ends with `CommandAborted = TRUE`. `–` is [`Effect::Continue`].
//!
//! V4.0 has no BufferMode (S7-1500T Motion Control V4.0 function manual, chapter 10
//! 'Instructions': no instruction has a BufferMode input): every job acts as PLCopen
//! `mcAborting` within these tables.
//!
//! # One row type for tables 1 and 2
//! [`NewJob`] is the union of the rows of both tables. Table 1 has a single row for "Halt,
//! MoveAbs, MoveRel, MoveVel, Jog, MotionInVel, MotionInPos"; table 2 splits it into
//! [`NewJob::Halt`], [`NewJob::Positioning`] and [`NewJob::MotionIn`]. In table 1 the three
//! rows therefore hold the same values. A job that is not a row of a table does not affect that
//! table's running jobs, so its row is all [`Effect::Continue`]. Two rows are like this, and they
//! are the only cells that are **derived** rather than copied from the manual:
//! - [`NewJob::Phasing`] in table 1 (phasing only acts on running gearing);
//! - [`NewJob::HomeAbortPassive`] (MC_Home mode 9) in table 2 (it only ends passive homing).
//!
//! # Pending and active synchronous jobs
//! *Pending* means `Busy` with neither `StartSync` nor `InSync`; *active* means `StartSync` or
//! `InSync`. A new MC_GearInPos / MC_CamIn is first evaluated as `…Pending`. It aborts only
//! other pending sync jobs, and no motion job in table 1. When it starts synchronizing
//! (`StartSync` rises), evaluate it again as `…Active`: that is when it aborts the running
//! single-axis motion and the previously active synchronous operation. This gives seamless cam
//! and gear changes (S7-1500T Motion Control V4.0 function manual, 10.16 'Override response of
//! Motion Control jobs V4', notes under table 2).
//!
//! # Table versus note
//! The note under table 2 says a pending sync job "can only be overridden by a further
//! synchronous operation job on the same following axis" or cancelled by MC_Power. The table
//! itself also marks MC_MotionInVelocity / MC_MotionInPosition as aborting a pending
//! MC_GearInPos and MC_CamIn (`A`, checked against the original). Tandem follows
//! the table as printed: MotionIn takes over the axis setpoints, which a pending sync job would
//! later have to abort anyway.
//!
//! # Not in these tables
//! - Never aborted by any job: MC_Power, MC_Reset, MC_SetSensor, MC_TorqueLimiting,
//!   MC_TorqueAdditive, MC_TorqueRange, MC_SynchronizedMotionSimulation, MC_InterpolateCam,
//!   MC_GetCam*. MC_OutputCam and MC_CamTrack end only through their own `Enable = FALSE`.
//! - Everything on the TO is aborted by MC_Power `Enable = FALSE`, by a technology alarm with a
//!   stopping reaction (see [`crate::catalog::alarm::Reaction::aborts_jobs`]), and by RUN→STOP.
//! - MC_Home modes 0/1/6/7 (direct homing, absolute adjustment) abort no motion or sync job
//!   (S7-1500T Motion Control V4.0 function manual, 3.2.9.11 'Direct homing'). Modes 2/8/10
//!   (passive homing) abort no motion or sync job either (3.2.9.7 to 3.2.9.9, passive homing). The
//!   manual does not say what a new passive homing job does to a running one;
//!   [`NewJob::from_home_mode`] returns `None` for these modes and leaves that to the caller.

/// Effect of a new job on a running job.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum Effect {
    /// `A`: the running job is aborted (`CommandAborted = TRUE`).
    Abort,
    /// `–`: no effect; the running job continues.
    Continue,
}

impl Effect {
    /// `true` for [`Effect::Abort`].
    pub const fn aborts(self) -> bool {
        matches!(self, Effect::Abort)
    }
}

/// Row of tables 1 and 2: the new job (S7-1500T Motion Control V4.0 function manual, 10.16
/// 'Override response of Motion Control jobs V4').
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum NewJob {
    /// MC_Home mode 3 or 5 (active homing).
    #[doc(alias = "MC_Home")]
    HomeActive = 0,
    /// MC_Home mode 9 (abort passive homing).
    HomeAbortPassive = 1,
    /// MC_Halt.
    #[doc(alias = "MC_Halt")]
    Halt = 2,
    /// MC_MoveAbsolute, MC_MoveRelative, MC_MoveVelocity, MC_MoveJog.
    #[doc(alias = "MC_MoveAbsolute")]
    #[doc(alias = "MC_MoveRelative")]
    #[doc(alias = "MC_MoveVelocity")]
    #[doc(alias = "MC_MoveJog")]
    Positioning = 3,
    /// MC_MotionInVelocity, MC_MotionInPosition.
    #[doc(alias = "MC_MotionInVelocity")]
    #[doc(alias = "MC_MotionInPosition")]
    MotionIn = 4,
    /// MC_MoveSuperimposed.
    #[doc(alias = "MC_MoveSuperimposed")]
    Superimposed = 5,
    /// MC_GearIn.
    #[doc(alias = "MC_GearIn")]
    GearIn = 6,
    /// MC_GearInPos, pending (`Busy`, neither `StartSync` nor `InSync`).
    #[doc(alias = "MC_GearInPos")]
    GearInPosPending = 7,
    /// MC_GearInPos, active (`StartSync` or `InSync`).
    GearInPosActive = 8,
    /// MC_PhasingAbsolute, MC_PhasingRelative.
    #[doc(alias = "MC_PhasingAbsolute")]
    #[doc(alias = "MC_PhasingRelative")]
    Phasing = 9,
    /// MC_CamIn, pending (`Busy`, neither `StartSync` nor `InSync`).
    #[doc(alias = "MC_CamIn")]
    CamInPending = 10,
    /// MC_CamIn, active (`StartSync` or `InSync`).
    CamInActive = 11,
}

impl NewJob {
    /// Number of rows.
    pub const COUNT: usize = 12;

    /// All rows, in table order.
    pub const ALL: [NewJob; NewJob::COUNT] = [
        NewJob::HomeActive,
        NewJob::HomeAbortPassive,
        NewJob::Halt,
        NewJob::Positioning,
        NewJob::MotionIn,
        NewJob::Superimposed,
        NewJob::GearIn,
        NewJob::GearInPosPending,
        NewJob::GearInPosActive,
        NewJob::Phasing,
        NewJob::CamInPending,
        NewJob::CamInActive,
    ];

    /// Row for an MC_Home job: mode 3/5 → [`NewJob::HomeActive`], mode 9 →
    /// [`NewJob::HomeAbortPassive`]. Other modes are not rows of tables 1/2 (they abort no motion
    /// or synchronous job) and give `None`.
    pub const fn from_home_mode(mode: u8) -> Option<NewJob> {
        match mode {
            3 | 5 => Some(NewJob::HomeActive),
            9 => Some(NewJob::HomeAbortPassive),
            _ => None,
        }
    }
}

/// Column of table 1: the running homing or motion job (S7-1500T Motion Control V4.0 function
/// manual, 10.16 'Override response of Motion Control jobs V4').
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum RunningMotion {
    /// MC_Home mode 2, 8 or 10 (passive homing).
    #[doc(alias = "MC_Home")]
    HomingPassive = 0,
    /// MC_Home mode 3 or 5 (active homing).
    HomingActive = 1,
    /// MC_Halt, MC_MoveAbsolute, MC_MoveRelative, MC_MoveVelocity, MC_MoveJog.
    #[doc(alias = "MC_Halt")]
    #[doc(alias = "MC_MoveAbsolute")]
    #[doc(alias = "MC_MoveRelative")]
    #[doc(alias = "MC_MoveVelocity")]
    #[doc(alias = "MC_MoveJog")]
    Motion = 2,
    /// MC_MoveSuperimposed.
    #[doc(alias = "MC_MoveSuperimposed")]
    Superimposed = 3,
    /// MC_MotionInVelocity, MC_MotionInPosition.
    #[doc(alias = "MC_MotionInVelocity")]
    #[doc(alias = "MC_MotionInPosition")]
    MotionIn = 4,
}

impl RunningMotion {
    /// Number of columns.
    pub const COUNT: usize = 5;

    /// All columns, in table order.
    pub const ALL: [RunningMotion; RunningMotion::COUNT] = [
        RunningMotion::HomingPassive,
        RunningMotion::HomingActive,
        RunningMotion::Motion,
        RunningMotion::Superimposed,
        RunningMotion::MotionIn,
    ];

    /// Column for a running MC_Home job: mode 2/8/10 → passive, 3/5 → active. Other modes finish
    /// at once (0/1/6/7) or are not running homing jobs (9), and give `None`.
    pub const fn from_home_mode(mode: u8) -> Option<RunningMotion> {
        match mode {
            2 | 8 | 10 => Some(RunningMotion::HomingPassive),
            3 | 5 => Some(RunningMotion::HomingActive),
            _ => None,
        }
    }
}

/// Column of table 2: the running synchronous-operation job (S7-1500T Motion Control V4.0 function
/// manual, 10.16 'Override response of Motion Control jobs V4').
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum RunningSync {
    /// MC_GearIn.
    #[doc(alias = "MC_GearIn")]
    GearIn = 0,
    /// MC_GearInPos, pending (`Busy`, neither `StartSync` nor `InSync`).
    #[doc(alias = "MC_GearInPos")]
    GearInPosPending = 1,
    /// MC_GearInPos, active (`StartSync` or `InSync`).
    GearInPosActive = 2,
    /// MC_PhasingAbsolute, MC_PhasingRelative.
    #[doc(alias = "MC_PhasingAbsolute")]
    #[doc(alias = "MC_PhasingRelative")]
    Phasing = 3,
    /// MC_CamIn, pending (`Busy`, neither `StartSync` nor `InSync`).
    #[doc(alias = "MC_CamIn")]
    CamInPending = 4,
    /// MC_CamIn, active (`StartSync` or `InSync`).
    CamInActive = 5,
}

impl RunningSync {
    /// Number of columns.
    pub const COUNT: usize = 6;

    /// All columns, in table order.
    pub const ALL: [RunningSync; RunningSync::COUNT] = [
        RunningSync::GearIn,
        RunningSync::GearInPosPending,
        RunningSync::GearInPosActive,
        RunningSync::Phasing,
        RunningSync::CamInPending,
        RunningSync::CamInActive,
    ];

    /// `true` for the pending states (`Busy`, neither `StartSync` nor `InSync`).
    pub const fn is_pending(self) -> bool {
        matches!(
            self,
            RunningSync::GearInPosPending | RunningSync::CamInPending
        )
    }
}

/// Row of table 3: a new job that may abort a running measuring job (S7-1500T Motion Control V4.0
/// function manual, 10.16 'Override response of Motion Control jobs V4').
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum NewMeasuringJob {
    /// MC_Home mode 2, 3, 5, 8, 9 or 10.
    #[doc(alias = "MC_Home")]
    HomeAborting = 0,
    /// MC_Home mode 0, 1, 6 or 7.
    HomeDirect = 1,
    /// MC_MeasuringInput.
    #[doc(alias = "MC_MeasuringInput")]
    MeasuringInput = 2,
    /// MC_MeasuringInputCyclic.
    #[doc(alias = "MC_MeasuringInputCyclic")]
    MeasuringInputCyclic = 3,
    /// MC_AbortMeasuringInput.
    #[doc(alias = "MC_AbortMeasuringInput")]
    AbortMeasuringInput = 4,
}

impl NewMeasuringJob {
    /// Number of rows.
    pub const COUNT: usize = 5;

    /// All rows, in table order.
    pub const ALL: [NewMeasuringJob; NewMeasuringJob::COUNT] = [
        NewMeasuringJob::HomeAborting,
        NewMeasuringJob::HomeDirect,
        NewMeasuringJob::MeasuringInput,
        NewMeasuringJob::MeasuringInputCyclic,
        NewMeasuringJob::AbortMeasuringInput,
    ];

    /// Row for an MC_Home job of the given mode. Modes outside the manual's list (4, 11 and
    /// above, which MC_Home rejects with `16#800A`) map to [`NewMeasuringJob::HomeDirect`]
    /// (no effect).
    pub const fn from_home_mode(mode: u8) -> NewMeasuringJob {
        if home_mode_aborts_measuring(mode) {
            NewMeasuringJob::HomeAborting
        } else {
            NewMeasuringJob::HomeDirect
        }
    }
}

/// Column of table 3: the running measuring job.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum RunningMeasuring {
    /// MC_MeasuringInput.
    #[doc(alias = "MC_MeasuringInput")]
    MeasuringInput = 0,
    /// MC_MeasuringInputCyclic.
    #[doc(alias = "MC_MeasuringInputCyclic")]
    MeasuringInputCyclic = 1,
}

impl RunningMeasuring {
    /// Number of columns.
    pub const COUNT: usize = 2;

    /// All columns, in table order.
    pub const ALL: [RunningMeasuring; RunningMeasuring::COUNT] = [
        RunningMeasuring::MeasuringInput,
        RunningMeasuring::MeasuringInputCyclic,
    ];
}

const A: Effect = Effect::Abort;
const C: Effect = Effect::Continue;

/// Table 1: effect of a new job ([`NewJob`], rows) on running homing and motion jobs
/// ([`RunningMotion`], columns). S7-1500T Motion Control V4.0 function manual, 10.16 'Override
/// response of Motion Control jobs V4'.
pub const TABLE1: [[Effect; RunningMotion::COUNT]; NewJob::COUNT] = [
    //   H-pas H-act Mot Sup MIn
    [A, A, A, A, A], // HomeActive (MC_Home 3/5)
    [A, C, C, C, C], // HomeAbortPassive (MC_Home 9)
    [C, A, A, A, A], // Halt
    [C, A, A, A, A], // Positioning (MoveAbs/Rel/Vel/Jog)
    [C, A, A, A, A], // MotionIn
    [C, C, C, A, C], // Superimposed
    [C, A, A, A, C], // GearIn
    [C, C, C, C, C], // GearInPosPending
    [C, A, A, A, C], // GearInPosActive
    [C, C, C, C, C], // Phasing (not a row of table 1: derived)
    [C, C, C, C, C], // CamInPending
    [C, A, A, A, C], // CamInActive
];

/// Table 2: effect of a new job ([`NewJob`], rows) on running synchronous-operation jobs
/// ([`RunningSync`], columns). S7-1500T Motion Control V4.0 function manual, 10.16 'Override
/// response of Motion Control jobs V4'.
pub const TABLE2: [[Effect; RunningSync::COUNT]; NewJob::COUNT] = [
    //   GearIn GIPpend GIPact Phasing CamPend CamAct
    [A, C, C, C, C, C], // HomeActive (MC_Home 3/5)
    [C, C, C, C, C, C], // HomeAbortPassive (not a row of table 2: derived)
    [A, C, A, A, C, A], // Halt
    [A, C, A, A, C, A], // Positioning (MoveAbs/Rel/Vel/Jog)
    [A, A, A, C, A, A], // MotionIn
    [C, C, C, C, C, C], // Superimposed
    [A, A, A, A, A, A], // GearIn
    [C, A, C, C, A, C], // GearInPosPending
    [A, A, A, A, A, A], // GearInPosActive
    [C, C, C, A, C, C], // Phasing
    [C, A, C, C, A, C], // CamInPending
    [A, A, A, A, A, A], // CamInActive
];

/// Table 3: effect of a new job ([`NewMeasuringJob`], rows) on running measuring jobs
/// ([`RunningMeasuring`], columns). S7-1500T Motion Control V4.0 function manual, 10.16 'Override
/// response of Motion Control jobs V4'.
pub const TABLE3: [[Effect; RunningMeasuring::COUNT]; NewMeasuringJob::COUNT] = [
    //   MeasIn MeasInCyclic
    [A, A], // HomeAborting (MC_Home 2/3/5/8/9/10)
    [C, C], // HomeDirect (MC_Home 0/1/6/7)
    [A, A], // MeasuringInput
    [A, A], // MeasuringInputCyclic
    [A, A], // AbortMeasuringInput
];

/// Table 1 lookup: does `new` abort the running homing/motion job `running`?
pub const fn table1(new: NewJob, running: RunningMotion) -> Effect {
    // In range by construction: the discriminants are 0..COUNT, and COUNT is the array size.
    TABLE1[new as usize][running as usize]
}

/// Table 2 lookup: does `new` abort the running synchronous-operation job `running`?
pub const fn table2(new: NewJob, running: RunningSync) -> Effect {
    TABLE2[new as usize][running as usize]
}

/// Table 3 lookup: does `new` abort the running measuring job `running`?
pub const fn table3(new: NewMeasuringJob, running: RunningMeasuring) -> Effect {
    TABLE3[new as usize][running as usize]
}

/// Table 3 for MC_Home: modes 2, 3, 5, 8, 9 and 10 abort running measuring jobs; 0, 1, 6 and 7
/// do not. Modes the manual does not define (4, 11+) give `false`.
pub const fn home_mode_aborts_measuring(mode: u8) -> bool {
    matches!(mode, 2 | 3 | 5 | 8 | 9 | 10)
}

// The enums' COUNT must match their variant lists (the arrays above are sized by COUNT, and
// `ALL` has COUNT entries whose discriminants are checked in the tests).
const _: () = assert!(NewJob::ALL.len() == NewJob::COUNT);
const _: () = assert!(RunningMotion::ALL.len() == RunningMotion::COUNT);
const _: () = assert!(RunningSync::ALL.len() == RunningSync::COUNT);
const _: () = assert!(NewMeasuringJob::ALL.len() == NewMeasuringJob::COUNT);
const _: () = assert!(RunningMeasuring::ALL.len() == RunningMeasuring::COUNT);

#[cfg(test)]
mod tests {
    use super::*;

    /// Parse a grid row: `A` → Abort, `–` or `-` → Continue; everything before `|` is a label.
    fn parse(row: &str) -> Vec<Effect> {
        let cells = row.split('|').nth(1).unwrap_or("");
        cells
            .split_whitespace()
            .map(|c| match c {
                "A" => Effect::Abort,
                "–" | "-" => Effect::Continue,
                other => {
                    assert!(other.is_empty(), "bad cell {other:?}");
                    Effect::Continue
                }
            })
            .collect()
    }

    fn rows(grid: &str) -> Vec<Vec<Effect>> {
        grid.lines()
            .filter(|l| l.contains('|'))
            .map(parse)
            .collect()
    }

    // Literal copy of S7-1500T Motion Control V4.0 function manual, 10.16 'Override response of
    // Motion Control jobs V4' table 1 (columns: H-pas, H-act, Mot, Sup, MIn).
    const MANUAL_TABLE1: &str = "
        MC_Home 3/5                                              | A A A A A
        MC_Home 9                                                | A – – – –
        Halt, MoveAbs, MoveRel, MoveVel, Jog, MotionInVel/Pos    | – A A A A
        MoveSuperimposed                                         | – – – A –
        GearIn                                                   | – A A A –
        GearInPos / CamIn pending                                | – – – – –
        GearInPos / CamIn active                                 | – A A A –
    ";

    // Literal copy of S7-1500T Motion Control V4.0 function manual, 10.16 'Override response of
    // Motion Control jobs V4' table 2 (columns: GearIn, GearInPos pend., GearInPos act., Phasing,
    // CamIn pend., CamIn act.).
    const MANUAL_TABLE2: &str = "
        MC_Home 3/5                       | A – – – – –
        MC_Halt                           | A – A A – A
        MoveAbs, MoveRel, MoveVel, Jog    | A – A A – A
        MotionInVel, MotionInPos          | A A A – A A
        MoveSuperimposed                  | – – – – – –
        GearIn                            | A A A A A A
        GearInPos pending                 | – A – – A –
        GearInPos active                  | A A A A A A
        PhasingAbs, PhasingRel            | – – – A – –
        CamIn pending                     | – A – – A –
        CamIn active                      | A A A A A A
    ";

    // Literal copy of S7-1500T Motion Control V4.0 function manual, 10.16 'Override response of
    // Motion Control jobs V4' table 3 (columns: MeasuringInput, MeasuringInputCyclic).
    const MANUAL_TABLE3: &str = "
        MC_Home 2/3/5/8/9/10                                     | A A
        MC_Home 0/1/6/7                                          | – –
        MeasuringInput, MeasuringInputCyclic, AbortMeasuringInput | A A
    ";

    #[test]
    fn discriminants_match_all_order() {
        for (i, r) in NewJob::ALL.iter().enumerate() {
            assert_eq!(*r as usize, i);
        }
        for (i, c) in RunningMotion::ALL.iter().enumerate() {
            assert_eq!(*c as usize, i);
        }
        for (i, c) in RunningSync::ALL.iter().enumerate() {
            assert_eq!(*c as usize, i);
        }
        for (i, r) in NewMeasuringJob::ALL.iter().enumerate() {
            assert_eq!(*r as usize, i);
        }
        for (i, c) in RunningMeasuring::ALL.iter().enumerate() {
            assert_eq!(*c as usize, i);
        }
    }

    #[test]
    fn table1_every_cell() {
        let grid = rows(MANUAL_TABLE1);
        // Manual row → NewJob rows it covers.
        let map: [&[NewJob]; 7] = [
            &[NewJob::HomeActive],
            &[NewJob::HomeAbortPassive],
            &[NewJob::Halt, NewJob::Positioning, NewJob::MotionIn],
            &[NewJob::Superimposed],
            &[NewJob::GearIn],
            &[NewJob::GearInPosPending, NewJob::CamInPending],
            &[NewJob::GearInPosActive, NewJob::CamInActive],
        ];
        assert_eq!(grid.len(), map.len());
        let mut covered = Vec::new();
        for (expected, news) in grid.iter().zip(map) {
            assert_eq!(expected.len(), RunningMotion::COUNT);
            for &new in news {
                covered.push(new);
                for (&running, &e) in RunningMotion::ALL.iter().zip(expected) {
                    assert_eq!(table1(new, running), e, "{new:?} vs running {running:?}");
                }
            }
        }
        // Rows absent from table 1 affect nothing there.
        for new in NewJob::ALL {
            if !covered.contains(&new) {
                assert_eq!(new, NewJob::Phasing);
                for running in RunningMotion::ALL {
                    assert_eq!(table1(new, running), Effect::Continue);
                }
            }
        }
    }

    #[test]
    fn table2_every_cell() {
        let grid = rows(MANUAL_TABLE2);
        let map: [&[NewJob]; 11] = [
            &[NewJob::HomeActive],
            &[NewJob::Halt],
            &[NewJob::Positioning],
            &[NewJob::MotionIn],
            &[NewJob::Superimposed],
            &[NewJob::GearIn],
            &[NewJob::GearInPosPending],
            &[NewJob::GearInPosActive],
            &[NewJob::Phasing],
            &[NewJob::CamInPending],
            &[NewJob::CamInActive],
        ];
        assert_eq!(grid.len(), map.len());
        let mut covered = Vec::new();
        for (expected, news) in grid.iter().zip(map) {
            assert_eq!(expected.len(), RunningSync::COUNT);
            for &new in news {
                covered.push(new);
                for (&running, &e) in RunningSync::ALL.iter().zip(expected) {
                    assert_eq!(table2(new, running), e, "{new:?} vs running {running:?}");
                }
            }
        }
        for new in NewJob::ALL {
            if !covered.contains(&new) {
                assert_eq!(new, NewJob::HomeAbortPassive);
                for running in RunningSync::ALL {
                    assert_eq!(table2(new, running), Effect::Continue);
                }
            }
        }
    }

    #[test]
    fn table3_every_cell() {
        let grid = rows(MANUAL_TABLE3);
        let map: [&[NewMeasuringJob]; 3] = [
            &[NewMeasuringJob::HomeAborting],
            &[NewMeasuringJob::HomeDirect],
            &[
                NewMeasuringJob::MeasuringInput,
                NewMeasuringJob::MeasuringInputCyclic,
                NewMeasuringJob::AbortMeasuringInput,
            ],
        ];
        assert_eq!(grid.len(), map.len());
        let mut n = 0;
        for (expected, news) in grid.iter().zip(map) {
            assert_eq!(expected.len(), RunningMeasuring::COUNT);
            for &new in news {
                n += 1;
                for (&running, &e) in RunningMeasuring::ALL.iter().zip(expected) {
                    assert_eq!(table3(new, running), e, "{new:?} vs running {running:?}");
                }
            }
        }
        assert_eq!(n, NewMeasuringJob::COUNT);
    }

    #[test]
    fn home_modes() {
        for mode in 0..=u8::MAX {
            let expected = [2, 3, 5, 8, 9, 10].contains(&mode);
            assert_eq!(home_mode_aborts_measuring(mode), expected, "mode {mode}");
            let row = NewMeasuringJob::from_home_mode(mode);
            for running in RunningMeasuring::ALL {
                assert_eq!(table3(row, running).aborts(), expected);
            }
        }
        assert_eq!(NewJob::from_home_mode(3), Some(NewJob::HomeActive));
        assert_eq!(NewJob::from_home_mode(5), Some(NewJob::HomeActive));
        assert_eq!(NewJob::from_home_mode(9), Some(NewJob::HomeAbortPassive));
        for mode in [0, 1, 2, 4, 6, 7, 8, 10, 11] {
            assert_eq!(NewJob::from_home_mode(mode), None);
        }
        for mode in [2, 8, 10] {
            assert_eq!(
                RunningMotion::from_home_mode(mode),
                Some(RunningMotion::HomingPassive)
            );
        }
        for mode in [3, 5] {
            assert_eq!(
                RunningMotion::from_home_mode(mode),
                Some(RunningMotion::HomingActive)
            );
        }
        for mode in [0, 1, 4, 6, 7, 9, 11] {
            assert_eq!(RunningMotion::from_home_mode(mode), None);
        }
    }

    #[test]
    fn consequences_stated_in_the_manual() {
        // Passive homing survives all motion jobs.
        for new in [
            NewJob::Halt,
            NewJob::Positioning,
            NewJob::MotionIn,
            NewJob::Superimposed,
        ] {
            assert!(!table1(new, RunningMotion::HomingPassive).aborts());
        }
        // A pending sync job aborts nothing in table 1.
        for running in RunningMotion::ALL {
            assert!(!table1(NewJob::GearInPosPending, running).aborts());
            assert!(!table1(NewJob::CamInPending, running).aborts());
        }
        // A pending sync job is replaced only by another sync job, except that MotionIn also
        // aborts it as printed (the table/note discrepancy documented in the module docs).
        for new in NewJob::ALL {
            let is_sync = matches!(
                new,
                NewJob::GearIn
                    | NewJob::GearInPosPending
                    | NewJob::GearInPosActive
                    | NewJob::CamInPending
                    | NewJob::CamInActive
            );
            for running in RunningSync::ALL.into_iter().filter(|r| r.is_pending()) {
                let expected = is_sync || new == NewJob::MotionIn;
                assert_eq!(
                    table2(new, running).aborts(),
                    expected,
                    "{new:?} vs pending {running:?}"
                );
            }
        }
        // A new pending sync job leaves an active sync running.
        for running in [
            RunningSync::GearIn,
            RunningSync::GearInPosActive,
            RunningSync::CamInActive,
        ] {
            assert!(!table2(NewJob::CamInPending, running).aborts());
            assert!(!table2(NewJob::GearInPosPending, running).aborts());
        }
        assert!(Effect::Abort.aborts());
        assert!(!Effect::Continue.aborts());
    }
}
