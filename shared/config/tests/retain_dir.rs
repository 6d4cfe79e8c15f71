//! `[cell] retain_dir`: where the nodes keep their retained data (docs/io.md, "Retained
//! data"), relative to the cell file's directory, `retain` by default; each node in
//! `<retain_dir>/<cell name>/<node name>/`.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::{Path, PathBuf};
use tandem_config::{load, parse, Problem};

const CELL: &str = "[cell]\nname = \"press\"\n\n[[nodes]]\nname = \"n1\"\ncycle_us = 1000\n";

/// `src` written as `cell.toml` in a fresh directory, loaded.
fn loaded(tag: &str, src: &str) -> (PathBuf, tandem_config::Cell) {
    let dir = std::env::temp_dir().join(format!("tandem-retain-dir-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("cell.toml");
    std::fs::write(&p, src).unwrap();
    let cell = load(&p).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    (dir, cell)
}

#[test]
fn the_default_is_retain_beside_the_cell_file() {
    let (dir, cell) = loaded("default", CELL);
    assert_eq!(cell.retain_dir, dir.join("retain"));
    assert_eq!(
        cell.node_retain_dir(0).unwrap(),
        dir.join("retain").join("press").join("n1")
    );
    assert_eq!(cell.node_retain_dir(1), None);
    // Parsed from text: relative to the current directory.
    let cell = parse("cell.toml", CELL).unwrap();
    assert_eq!(cell.retain_dir, Path::new("retain"));
}

#[test]
fn a_relative_key_is_beside_the_cell_file_an_absolute_one_as_given() {
    let src = CELL.replace(
        "name = \"press\"\n",
        "name = \"press\"\nretain_dir = \"state/x\"\n",
    );
    let (dir, cell) = loaded("relative", &src);
    assert_eq!(cell.retain_dir, dir.join("state/x"));
    let src = CELL.replace(
        "name = \"press\"\n",
        "name = \"press\"\nretain_dir = \"/var/lib/tandem\"\n",
    );
    let (_, cell) = loaded("absolute", &src);
    assert_eq!(
        cell.node_retain_dir(0).unwrap(),
        Path::new("/var/lib/tandem/press/n1")
    );
}

#[test]
fn an_empty_key_is_refused_naming_it() {
    let src = CELL.replace(
        "name = \"press\"\n",
        "name = \"press\"\nretain_dir = \" \"\n",
    );
    let e = parse("cell.toml", &src).unwrap_err();
    assert_eq!((e.line, e.key.as_str()), (Some(3), "cell.retain_dir"));
    assert!(matches!(*e.problem, Problem::Invalid(_)), "{e}");
}
