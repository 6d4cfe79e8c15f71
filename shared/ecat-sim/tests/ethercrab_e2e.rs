//! End to end: unmodified ethercrab as the MainDevice against `tandem-ecat-sim` on a veth pair
//! inside a network namespace this test creates (it needs root and fails, never skips, when
//! it cannot create them).
//!
//! Proves: ethercrab finds exactly the emulated SubDevices with their identities, reads an
//! object over CoE, remaps the drive's TxPDO over CoE (and maps the new size), brings the
//! group to OP, distributes the reference clock's DC system time every cycle (it advances
//! and stays on the MainDevice's clock), exchanges the PDI for 1,000 cycles with the
//! expected working counter (drive +3, terminal +3), a digital output comes back on the
//! looped terminal's inputs one cycle later, and the drive's statusword follows the CiA 402
//! enable sequence for controlwords 0x06, 0x07, 0x0F.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic, unsafe_code)]

use std::os::fd::AsRawFd;
use std::process::Command;
use std::sync::mpsc;
use std::time::{Duration, Instant};

use ethercrab::std::{ethercat_now, tx_rx_task};
use ethercrab::{MainDevice, MainDeviceConfig, PduStorage, Timeouts};
use tandem_testkit::netns::{Background, VethNetns};

static PDU_STORAGE: PduStorage<16, { PduStorage::element_size(1100) }> = PduStorage::new();

/// Starts the emulator (drive and digital I/O, looped back) on `ecs` and waits 10 s at most for
/// it to say it runs both.
fn start_sim(ns: &VethNetns) -> Background {
    let mut c = Command::new("ip");
    c.args([
        "netns",
        "exec",
        ns.name(),
        env!("CARGO_BIN_EXE_tandem-ecat-sim"),
    ])
    .args(["--interface", "ecs", "--devices", "drive,dio", "--loopback"]);
    let (sim, line) = Background::start(&mut c, Duration::from_secs(10), "tandem-ecat-sim");
    assert!(line.contains("2 SubDevice(s) on ecs"), "{line}");
    sim
}

/// Enters the namespace on this thread (sockets opened afterwards live in it).
fn enter(ns: &str) {
    let file = std::fs::File::open(format!("/var/run/netns/{ns}")).expect("open netns");
    // SAFETY: `file` is an open namespace file descriptor for the duration of the call;
    // setns only changes this thread's network namespace.
    let rc = unsafe { libc::setns(file.as_raw_fd(), libc::CLONE_NEWNET) };
    assert_eq!(rc, 0, "setns: {}", std::io::Error::last_os_error());
}

/// What the MainDevice saw.
#[derive(Debug, Default)]
struct Seen {
    identities: Vec<(u32, u32, u32, u32, String)>,
    device_type: u32,
    working_counters: Vec<u16>,
    dio_mismatches: usize,
    statuswords: Vec<u16>,
    enabled_at: Option<usize>,
    /// The largest |DC system time of the reference − the MainDevice's clock| (ns).
    dc_deviation_ns: u64,
    last_system_time: u64,
    /// Cycles whose DC system time did not advance.
    dc_not_increasing: usize,
    /// (inputs, outputs) bytes of each SubDevice in OP.
    image_sizes: Vec<(usize, usize)>,
    /// Round trip of each cycle's `tx_rx` (ns), reported, not asserted.
    round_trips: Vec<u64>,
}

async fn main_device(seen: &mut Seen) -> Result<(), ethercrab::error::Error> {
    let (tx, rx, pdu_loop) = PDU_STORAGE.try_split().expect("split once");
    let md = MainDevice::new(
        pdu_loop,
        // The emulator is another process on a machine shared with compilers: a reply may be
        // later than ethercrab's 30 ms default, and a late reply ends its receive task.
        Timeouts {
            pdu: Duration::from_millis(500),
            ..Timeouts::default()
        },
        MainDeviceConfig {
            dc_static_sync_iterations: 100,
            ..MainDeviceConfig::default()
        },
    );
    tokio::spawn(tx_rx_task("ecm", tx, rx).expect("open ecm"));
    let group = md.init_single_group::<4, 64>(ethercat_now).await?;
    for sd in group.iter(&md) {
        let id = sd.identity();
        seen.identities.push((
            id.vendor_id,
            id.product_id,
            id.revision,
            id.serial,
            sd.name().to_string(),
        ));
        if sd.name() == "TSD-402" {
            seen.device_type = sd.sdo_read::<u32>(0x1000, 0).await?;
            sd.sdo_write(0x6060, 0, 8i8).await?;
            // Remap the TxPDO over CoE as a node would: statusword, mode display, position
            // and velocity actual (11 bytes instead of the default 21).
            sd.sdo_write_array(
                0x1A00,
                &[0x6041_0010u32, 0x6061_0008, 0x6064_0020, 0x606C_0020],
            )
            .await?;
        }
    }
    let group = group.into_safe_op(&md).await?;
    let group = group.request_into_op(&md).await?;
    let deadline = Instant::now() + Duration::from_secs(5);
    loop {
        let r = group.tx_rx(&md).await?;
        if r.all_op() {
            break;
        }
        assert!(Instant::now() < deadline, "OP not reached within 5 s");
        tokio::time::sleep(Duration::from_millis(1)).await;
    }
    for sd in group.iter(&md) {
        let io = sd.io_raw();
        seen.image_sizes
            .push((io.inputs().len(), io.outputs().len()));
    }
    let mut controlword = 0x06u16;
    for cycle in 0..1000usize {
        let value = (cycle as u8).wrapping_mul(37);
        for sd in group.iter(&md) {
            let mut o = sd.outputs_raw_mut();
            if sd.name() == "EL1859" {
                o[0] = value;
            } else {
                o[0..2].copy_from_slice(&controlword.to_le_bytes());
                o[2] = 8;
            }
        }
        let sent = Instant::now();
        // With the FRMW of the reference clock's system time 0x0910 in front of the LRW.
        let response = group.tx_rx_sync_system_time(&md).await?;
        seen.round_trips.push(sent.elapsed().as_nanos() as u64);
        let system_time = response.extra.unwrap_or(0);
        let now = ethercat_now();
        seen.dc_deviation_ns = seen.dc_deviation_ns.max(now.abs_diff(system_time));
        if system_time <= seen.last_system_time {
            seen.dc_not_increasing += 1;
        }
        seen.last_system_time = system_time;
        seen.working_counters.push(response.working_counter);
        for sd in group.iter(&md) {
            // Copy the inputs out: the PDI lock must not be held while the outputs are taken.
            let i: Vec<u8> = sd.inputs_raw().to_vec();
            if sd.name() == "EL1859" {
                let previous = (cycle as u8).wrapping_sub(1).wrapping_mul(37);
                if cycle > 0 && i[0] != previous {
                    seen.dio_mismatches += 1;
                }
            } else {
                let sw = u16::from_le_bytes([i[0], i[1]]);
                if seen.statuswords.last() != Some(&sw) {
                    seen.statuswords.push(sw);
                }
                let position = [i[3], i[4], i[5], i[6]];
                let mut o = sd.outputs_raw_mut();
                // CSP: the set-point holds the actual position (no jump on enable).
                o[3..7].copy_from_slice(&position);
                controlword = match sw & 0x6F {
                    0x21 => 0x07,
                    0x23 | 0x27 => 0x0F,
                    _ => 0x06,
                };
                if sw & 0x6F == 0x27 && seen.enabled_at.is_none() {
                    seen.enabled_at = Some(cycle);
                }
            }
        }
        tokio::time::sleep(Duration::from_micros(500)).await;
    }
    Ok(())
}

#[test]
fn ethercrab_brings_the_emulated_segment_to_op_and_exchanges_pdi() {
    let ns = VethNetns::create("tecat", "ecm", "ecs");
    let _sim = start_sim(&ns);
    let (tx, rx) = mpsc::channel();
    let name = ns.name().to_string();
    std::thread::spawn(move || {
        enter(&name);
        let rt = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(1)
            .enable_time()
            .build()
            .expect("runtime");
        let mut seen = Seen::default();
        let result = rt.block_on(async {
            tokio::time::timeout(Duration::from_secs(60), main_device(&mut seen)).await
        });
        // The test may have timed out already; then nobody reads this.
        let _ = tx.send((
            result
                .map_err(|_| "timeout")
                .map(|r| r.map_err(|e| format!("{e:?}"))),
            seen,
        ));
    });
    let (result, seen) = rx
        .recv_timeout(Duration::from_secs(90))
        .expect("MainDevice thread did not finish within 90 s");
    result.expect("within 60 s").expect("ethercrab");
    assert_eq!(
        seen.identities,
        vec![
            (
                0x0054_444D,
                0x0000_0402,
                0x0001_0000,
                1,
                "TSD-402".to_string()
            ),
            (
                0x0000_0002,
                0x0743_3052,
                0x0010_0000,
                2,
                "EL1859".to_string()
            ),
        ]
    );
    assert_eq!(seen.device_type, 0x0002_0192);
    assert_eq!(seen.image_sizes, vec![(11, 9), (1, 1)]);
    // The drive, the first DC SubDevice, is the reference clock: its system time (local
    // CLOCK_MONOTONIC + the offset ethercrab wrote at init) advances every cycle and stays on
    // the MainDevice's clock (the bound is generous: the time is read in flight, the clock
    // after the reply).
    assert_eq!(seen.dc_not_increasing, 0);
    assert!(
        seen.dc_deviation_ns < 50_000_000,
        "{} ns",
        seen.dc_deviation_ns
    );
    assert_eq!(seen.working_counters.len(), 1000);
    assert!(
        seen.working_counters.iter().all(|&w| w == 6),
        "working counters {:?}",
        &seen.working_counters[..10]
    );
    assert_eq!(seen.dio_mismatches, 0);
    // Switch on disabled → ready to switch on → switched on → operation enabled.
    let states: Vec<u16> = seen.statuswords.iter().map(|sw| sw & 0x6F).collect();
    let tail: Vec<u16> = states
        .iter()
        .copied()
        .skip_while(|s| *s != 0x40 && *s != 0x60)
        .collect();
    assert_eq!(
        tail.iter().map(|s| s & 0x2F).collect::<Vec<_>>(),
        vec![0x00, 0x21, 0x23, 0x27],
        "{:x?}",
        seen.statuswords
    );
    assert!(
        seen.enabled_at.is_some_and(|c| c < 20),
        "{:?}",
        seen.enabled_at
    );
    let mut rt = seen.round_trips.clone();
    rt.sort_unstable();
    eprintln!(
        "DC system time vs ethercat_now(): max deviation {} us",
        seen.dc_deviation_ns / 1000
    );
    eprintln!(
        "PDI round trip over the veth pair (2 SubDevices, FRMW 0x0910 + 22 B LRW + 2 FPRD), {} cycles: p50 {} us, p99 {} us, max {} us",
        rt.len(),
        rt[rt.len() / 2] / 1000,
        rt[rt.len() * 99 / 100] / 1000,
        rt[rt.len() - 1] / 1000
    );
}
