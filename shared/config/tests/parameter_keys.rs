//! MC_WriteParameter / MC_ReadParameter in scripts, `tandem cmd` and the Zenoh command JSON
//! (which become a script entry): `tag` is the S7-1500T tag name (or its number), `value` a
//! number or a boolean; an unknown tag name becomes number 0, which the axis refuses with
//! 16#8080 (docs/parameters.md).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_config::script;
use tandem_motion::objects::action::Action;
use tandem_motion::objects::axis::{axis_parameter_number, Command};

fn entry(instruction: &str, params: &str) -> Result<Action, String> {
    let src = format!(
        "[sim]\nduration = 1\n[[at]]\nt = 0\naxis = \"x\"\ninstruction = \"{instruction}\"\n\
         {params}\n"
    );
    script::parse("s.toml", &src, &["x"], &[])
        .map(|s| s.entries[0].action)
        .map_err(|e| e.to_string())
}

fn n(tag: &str) -> u16 {
    axis_parameter_number(tag).unwrap()
}

#[test]
fn tags_by_name_or_number_values_as_numbers_or_booleans() {
    assert_eq!(
        entry(
            "MC_WriteParameter",
            "tag = \"DynamicLimits.MaxJerk\"\nvalue = 50000"
        ),
        Ok(Action::Command(Command::WriteParameter {
            parameter: n("DynamicLimits.MaxJerk"),
            value: 50_000.0
        }))
    );
    assert_eq!(
        entry(
            "MC_WriteParameter",
            "tag = \"PositionLimits_SW.Active\"\nvalue = true"
        ),
        Ok(Action::Command(Command::WriteParameter {
            parameter: n("PositionLimits_SW.Active"),
            value: 1.0
        }))
    );
    assert_eq!(
        entry("MC_ReadParameter", "tag = 3"),
        Ok(Action::Command(Command::ReadParameter { parameter: 3 }))
    );
    // Unknown names and numbers reach the axis as number 0 (16#8080 there).
    assert_eq!(
        entry("MC_ReadParameter", "tag = \"DynamicLimits.Nonsense\""),
        Ok(Action::Command(Command::ReadParameter { parameter: 0 }))
    );
    assert_eq!(
        entry("MC_WriteParameter", "tag = -4\nvalue = 1"),
        Ok(Action::Command(Command::WriteParameter {
            parameter: 0,
            value: 1.0
        }))
    );
    let missing = entry("MC_WriteParameter", "tag = 3").unwrap_err();
    assert!(missing.contains("value"), "{missing}");
}

#[test]
fn parameters_on_the_command_line() {
    // `tandem cmd main/slide MC_WriteParameter --tag DynamicLimits.MaxJerk --value 50000`.
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let cell = tandem_config::load(&root.join("config/example-cell.toml")).unwrap();
    let params = vec![
        ("tag".to_string(), "DynamicLimits.MaxJerk".to_string()),
        ("value".to_string(), "50000".to_string()),
    ];
    let e = script::parse_command(&cell, "slide", "MC_WriteParameter", &params).unwrap();
    assert_eq!(
        e.action,
        Action::Command(Command::WriteParameter {
            parameter: n("DynamicLimits.MaxJerk"),
            value: 50_000.0
        })
    );
    let read = vec![("tag".to_string(), "Homing.HomePosition".to_string())];
    let e = script::parse_command(&cell, "slide", "MC_ReadParameter", &read).unwrap();
    assert_eq!(
        e.action,
        Action::Command(Command::ReadParameter {
            parameter: n("Homing.HomePosition")
        })
    );
}
