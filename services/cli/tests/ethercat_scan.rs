//! `tandem ethercat scan` against the virtual segment (`tandem_ecat_sim`, run in this process
//! inside a network namespace with a veth pair that the test creates; it needs root and
//! fails, never skips, when it cannot): the listing is exactly what was emulated.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic, unsafe_code)]

use std::os::fd::AsRawFd;
use std::process::Command;
use std::sync::mpsc;
use std::time::Duration;
use tandem_testkit::netns::VethNetns;

#[test]
fn scan_lists_exactly_the_emulated_subdevices() {
    let ns = VethNetns::create("tscan", "ecm", "ecs");
    let path = ns.path();
    let (ready_tx, ready_rx) = mpsc::channel();
    std::thread::spawn(move || {
        let file = std::fs::File::open(&path).expect("open netns");
        // SAFETY: `file` is an open namespace descriptor for the duration of the call; setns
        // changes only this thread's network namespace.
        let rc = unsafe { libc::setns(file.as_raw_fd(), libc::CLONE_NEWNET) };
        assert_eq!(rc, 0, "setns");
        // The socket is open once the interface resolves; signal just before running.
        let args: Vec<String> = ["--interface", "ecs", "--devices", "dio,drive,dio"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        // The receiver waits for this signal; if it is gone the test has failed already.
        let _ = ready_tx.send(());
        // Runs until the namespace (and with it the interface) is deleted.
        let _ = tandem_ecat_sim::net::run(&args);
    });
    ready_rx
        .recv_timeout(Duration::from_secs(10))
        .expect("emulator thread started");
    std::thread::sleep(Duration::from_millis(200));
    let out = Command::new("timeout")
        .args([
            "60",
            "ip",
            "netns",
            "exec",
            ns.name(),
            env!("CARGO_BIN_EXE_tandem"),
            "ethercat",
            "scan",
            "ecm",
        ])
        .output()
        .expect("run tandem");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows: Vec<Vec<&str>> = stdout
        .lines()
        .map(|l| l.split_whitespace().collect())
        .collect();
    assert_eq!(
        rows[0],
        ["pos", "addr", "vendor", "product", "revision", "serial", "name", "in", "out", "dc"]
    );
    assert_eq!(
        &rows[1..4],
        &[
            [
                "0",
                "0x1000",
                "0x00000002",
                "0x07433052",
                "0x00100000",
                "1",
                "EL1859",
                "1",
                "1",
                "None"
            ],
            [
                "1",
                "0x1001",
                "0x0054444d",
                "0x00000402",
                "0x00010000",
                "2",
                "TSD-402",
                "21",
                "9",
                "Bits64"
            ],
            [
                "2",
                "0x1002",
                "0x00000002",
                "0x07433052",
                "0x00100000",
                "3",
                "EL1859",
                "1",
                "1",
                "None"
            ],
        ]
    );
    assert_eq!(rows[4], ["3", "SubDevice(s)"]);
    assert_eq!(rows.len(), 5);
}
