//! Bad input that used to pass `tandem check` and fail later (or never): names that cannot
//! stand in a service name, a key or a file name, node names the protocol's keys take, a
//! script that runs for a day, files too large to be a cell, a script or a cam, and bytes that
//! are not UTF-8. Each is refused naming the file, the line (where there is one) and the key.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::PathBuf;
use tandem_config::{parse, Problem};

const CELL: &str = "[cell]
name = \"c\"

[[nodes]]
name = \"n1\"
cycle_us = 1000

[axes.master]
node = \"n1\"
virtual = true

[axes.master.dynamics]
max_velocity = 2000.0
max_acceleration = 4000.0
max_deceleration = 4000.0
max_jerk = 40000.0
velocity = 800.0
acceleration = 3000.0
deceleration = 3000.0
jerk = 30000.0
emergency_deceleration = 8000.0
";

/// The error of `CELL` with `from` replaced by `to`: its line, key and problem.
fn refused(from: &str, to: &str) -> (Option<usize>, String, Problem) {
    assert!(CELL.contains(from), "{from}");
    let e = parse("cell.toml", &CELL.replacen(from, to, 1)).unwrap_err();
    (e.line, e.key.clone(), *e.problem)
}

/// A fresh directory under the target's temporary directory.
fn dir(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("bad_input_{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn the_cell_as_written_passes() {
    parse("cell.toml", CELL).unwrap();
}

#[test]
fn a_cell_name_of_300_characters_is_refused_at_check() {
    let long = "p".repeat(300);
    let (line, key, problem) = refused("name = \"c\"", &format!("name = \"{long}\""));
    assert_eq!((line, key.as_str()), (Some(2), "cell.name"));
    assert_eq!(
        problem,
        Problem::BadName {
            what: "cell",
            name: long
        }
    );
    // 64 characters are a name.
    let ok = CELL.replacen("name = \"c\"", &format!("name = \"{}\"", "p".repeat(64)), 1);
    parse("cell.toml", &ok).unwrap();
}

#[test]
fn names_that_cannot_stand_in_a_key_or_a_column_are_refused() {
    // `.` separates an axis from its column in a trace header; `/` and `*` are key syntax.
    for bad in ["mas.ter", "mas/ter", "m*", "mäster", ""] {
        let src = CELL.replace("[axes.master", &format!("[axes.\"{bad}\""));
        let e = parse("cell.toml", &src).unwrap_err();
        let (line, key, problem) = (e.line, e.key.clone(), *e.problem);
        assert_eq!(key, format!("axes.{bad}"), "{bad}: {problem}");
        assert_eq!(
            problem,
            Problem::BadName {
                what: "axis",
                name: bad.into()
            }
        );
        assert!(line.is_some(), "{bad}");
    }
}

#[test]
fn node_names_the_protocol_takes_are_refused() {
    for reserved in ["lv", "gateway", "clock", "alive"] {
        let src = CELL.replace("\"n1\"", &format!("\"{reserved}\""));
        let e = parse("cell.toml", &src).unwrap_err();
        assert_eq!((e.line, e.key.as_str()), (Some(5), "nodes[0].name"), "{e}");
        assert!(
            matches!(&*e.problem, Problem::ReservedName { name, .. } if name == reserved),
            "{e}"
        );
        assert!(e.to_string().contains("lv, gateway, clock, alive"), "{e}");
    }
}

#[test]
fn a_script_of_a_day_is_refused_and_an_hour_passes() {
    let cell = parse("cell.toml", CELL).unwrap();
    let script = |d: &str| {
        format!("[sim]\nduration = {d}\n\n[[at]]\nt = 0\naxis = \"master\"\ninstruction = \"MC_Power\"\n")
    };
    let e = tandem_config::script::parse_cell("s.toml", &script("86400"), &cell).unwrap_err();
    assert_eq!((e.line, e.key.as_str()), (Some(2), "sim.duration"), "{e}");
    assert!(e.to_string().contains("3600 (one hour)"), "{e}");
    let s = tandem_config::script::parse_cell("s.toml", &script("3600"), &cell).unwrap();
    assert_eq!(s.duration_ns, 3_600_000_000_000);
}

#[test]
fn files_too_large_are_refused_without_being_read_to_the_end() {
    let d = dir("large");
    let big = d.join("big.toml");
    let f = std::fs::File::create(&big).unwrap();
    f.set_len(tandem_config::read::CELL_FILE_MAX + 1).unwrap();
    let e = tandem_config::load(&big).unwrap_err();
    assert_eq!(e.file, big.display().to_string());
    assert_eq!(
        *e.problem,
        Problem::TooLarge {
            max: tandem_config::read::CELL_FILE_MAX
        }
    );
    // An endless file: refused after the cap, not read forever.
    let e = tandem_config::load(std::path::Path::new("/dev/zero")).unwrap_err();
    assert!(matches!(*e.problem, Problem::TooLarge { .. }), "{e}");
    let cell = parse("cell.toml", CELL).unwrap();
    let e = tandem_config::script::load(std::path::Path::new("/dev/zero"), &cell).unwrap_err();
    assert!(matches!(*e.problem, Problem::TooLarge { .. }), "{e}");
    // Exactly the cap is read.
    let exact = d.join("exact.toml");
    let mut text = CELL.to_string();
    let pad = tandem_config::read::CELL_FILE_MAX as usize - text.len();
    text.push_str(&"#".repeat(pad));
    std::fs::write(&exact, text).unwrap();
    tandem_config::load(&exact).unwrap();
}

#[test]
fn invalid_utf8_is_refused_naming_file_line_and_column() {
    let d = dir("utf8");
    let p = d.join("cell.toml");
    let mut bytes = CELL.as_bytes().to_vec();
    // Line 6 is `cycle_us = 1000`: a Latin-1 byte in its comment.
    let at = CELL.find("cycle_us = 1000").unwrap() + "cycle_us = 1000".len();
    bytes.splice(at..at, b"  # 10\xB5s".iter().copied());
    std::fs::write(&p, &bytes).unwrap();
    let e = tandem_config::load(&p).unwrap_err();
    assert_eq!(e.line, Some(6), "{e}");
    assert_eq!(
        *e.problem,
        Problem::NotUtf8 {
            column: 22,
            byte: 0xB5
        }
    );
    assert_eq!(
        e.to_string(),
        format!(
            "{}:6: not UTF-8 text: byte 0xB5 at column 22 is not valid UTF-8",
            p.display()
        )
    );
    // A script, and a cam's CSV, the same way.
    let cell = parse("cell.toml", CELL).unwrap();
    let s = d.join("script.toml");
    std::fs::write(&s, b"[sim]\nduration = 1\n\xFF\n").unwrap();
    let e = tandem_config::script::load(&s, &cell).unwrap_err();
    assert_eq!((e.line, e.file.clone()), (Some(3), s.display().to_string()));
    std::fs::write(d.join("cam.csv"), b"0,0\n1,1\n2,\xC3\n").unwrap();
    let with_cam = format!("{CELL}\n[cams.c]\npoints_csv = \"cam.csv\"\n");
    std::fs::write(&p, with_cam).unwrap();
    let e = tandem_config::load(&p).unwrap_err();
    assert_eq!(e.key, "cams.c.points_csv", "{e}");
    assert!(
        e.to_string()
            .contains(&format!("{}:3: not UTF-8", d.join("cam.csv").display())),
        "{e}"
    );
}
