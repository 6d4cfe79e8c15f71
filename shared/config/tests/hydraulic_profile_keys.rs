//! `nProfileType`, `fMaxJerk`, `nJerkEnabled` and `bTimeBased` of `[axes.<name>.hydraulic]`
//! (the Beckhoff hydraulic positioning library's `ST_TcHydAxParam`): the generator chosen by
//! the library's enumeration name or number, the jerk-limited transitions as a WORD (TOML's hex
//! literal), the time-based mode; each value out of range refused naming the key, and the
//! library's defaults when absent.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_config::{parse, Problem};
use tandem_motion::hydraulic::jerk_generator::{JerkParams, ProfileSelection, ProfileType};

const CELL: &str = include_str!("../../../config/hydraulic.toml");
const AT: &str = "fLagAmp = 50.0";

/// The bundled hydraulic cell with `keys` added to `[axes.ram.hydraulic]`.
fn with(keys: &str) -> Result<ProfileSelection, tandem_config::ConfigError> {
    assert!(CELL.contains(AT));
    let src = CELL.replacen(AT, &format!("{AT}\n{keys}"), 1);
    let cell = parse("hydraulic.toml", &src)?;
    Ok(cell.axes[0].config.hydraulic.unwrap().profile)
}

#[test]
fn the_generator_is_chosen_by_the_librarys_name_or_number() {
    // Absent: the library's defaults (CtrlBased, fMaxJerk 1000, nJerkEnabled 16#0101, not
    // time-based).
    assert_eq!(with("").unwrap(), ProfileSelection::default());
    assert_eq!(
        ProfileSelection::default().jerk,
        JerkParams {
            max_jerk: 1000.0,
            jerk_enabled: 0x0101
        }
    );
    for (v, want) in [
        ("\"iTcMc_ProfileJerkBased\"", ProfileType::JerkBased),
        ("5", ProfileType::JerkBased),
        ("\"iTcMc_ProfileCtrlBased\"", ProfileType::CtrlBased),
        ("3", ProfileType::CtrlBased),
        ("\"iTcMc_ProfileConstAcc\"", ProfileType::CtrlBased),
        ("0", ProfileType::CtrlBased),
    ] {
        let p = with(&format!("nProfileType = {v}")).unwrap();
        assert_eq!(p.profile_type, want, "{v}");
    }
    let p = with("nProfileType = 5\nfMaxJerk = 2500.0\nnJerkEnabled = 0x0103\nbTimeBased = true")
        .unwrap();
    assert_eq!(
        p,
        ProfileSelection {
            profile_type: ProfileType::JerkBased,
            jerk: JerkParams {
                max_jerk: 2500.0,
                jerk_enabled: 0x0103
            },
            time_based: true,
        }
    );
}

#[test]
fn values_out_of_range_are_refused_naming_the_key() {
    for (keys, key) in [
        ("nProfileType = \"iTcMc_ProfileTimeRamp\"", "nProfileType"),
        ("nProfileType = 4", "nProfileType"),
        ("nProfileType = 6", "nProfileType"),
        ("nProfileType = \"JerkBased\"", "nProfileType"),
        ("fMaxJerk = 0.0", "fMaxJerk"),
        ("fMaxJerk = -5.0", "fMaxJerk"),
        ("fMaxJerk = inf", "fMaxJerk"),
        ("nJerkEnabled = 0x0200", "nJerkEnabled"),
        ("nJerkEnabled = -1", "nJerkEnabled"),
        ("nJerkEnabled = 0x10101", "nJerkEnabled"),
    ] {
        let e = with(keys).unwrap_err();
        assert_eq!(e.key, format!("axes.ram.hydraulic.{key}"), "{keys}: {e}");
        if key == "nProfileType" {
            assert!(
                matches!(&*e.problem, Problem::NotOneOf { options, .. }
                    if options.iter().any(|o| o.contains("iTcMc_ProfileJerkBased (5)"))),
                "{e}"
            );
        }
    }
    // A wrong type is the TOML reader's refusal.
    assert!(with("bTimeBased = 1").is_err());
}
