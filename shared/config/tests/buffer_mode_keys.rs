//! `buffer_mode` in scripts (and so in `tandem cmd` and the Zenoh command JSON, which become a
//! script entry): the PLCopen name or number; the default is the plain (aborting) command.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_config::script;
use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::objects::action::Action;
use tandem_motion::objects::axis::{BufferMode, BufferedMotion, Command};

fn entry(params: &str) -> Result<Action, String> {
    let src = format!(
        "[sim]\nduration = 1\n[[at]]\nt = 0\naxis = \"x\"\ninstruction = \"MC_MoveRelative\"\n\
         distance = 5.0\n{params}\n"
    );
    script::parse("s.toml", &src, &["x"], &[])
        .map(|s| s.entries[0].action)
        .map_err(|e| e.to_string())
}

fn queued(buffer_mode: BufferMode) -> Action {
    Action::Command(Command::Buffered {
        motion: BufferedMotion::MoveRelative {
            distance: 5.0,
            dynamics: Dynamics::DEFAULT,
        },
        buffer_mode,
    })
}

#[test]
fn buffer_mode_by_name_or_number() {
    assert_eq!(
        entry("buffer_mode = \"BlendingLow\""),
        Ok(queued(BufferMode::BlendingLow))
    );
    assert_eq!(
        entry("buffer_mode = \"mcBuffered\""),
        Ok(queued(BufferMode::Buffered))
    );
    assert_eq!(
        entry("buffer_mode = 5"),
        Ok(queued(BufferMode::BlendingHigh))
    );
    assert_eq!(
        entry(""),
        Ok(Action::Command(Command::MoveRelative {
            distance: 5.0,
            dynamics: Dynamics::DEFAULT
        }))
    );
    assert_eq!(entry("buffer_mode = \"Aborting\""), entry(""));
    let bad = entry("buffer_mode = \"Sometimes\"").unwrap_err();
    assert!(bad.contains("buffer_mode"), "{bad}");
    let bad = entry("buffer_mode = 9").unwrap_err();
    assert!(bad.contains("0..5"), "{bad}");
}

#[test]
fn buffer_mode_on_the_command_line() {
    // `tandem cmd main/slide MC_MoveRelative --distance 5 --buffer_mode BlendingLow` and the
    // Zenoh command JSON (which becomes the same line) go through `parse_command`.
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let cell = tandem_config::load(&root.join("config/example-cell.toml")).unwrap();
    let params = |mode: &str| {
        vec![
            ("distance".to_string(), "5".to_string()),
            ("buffer_mode".to_string(), mode.to_string()),
        ]
    };
    let e =
        script::parse_command(&cell, "slide", "MC_MoveRelative", &params("BlendingLow")).unwrap();
    assert_eq!(e.action, queued(BufferMode::BlendingLow));
    let e = script::parse_command(&cell, "slide", "MoveRelative", &params("1")).unwrap();
    assert_eq!(e.action, queued(BufferMode::Buffered));
    let bad = script::parse_command(&cell, "slide", "MoveRelative", &params("Often")).unwrap_err();
    assert!(bad.to_string().contains("buffer_mode"), "{bad}");
}
