//! EtherCAT process data round trip (issue 13): `cargo bench -p tandem-bench --bench ethercat`
//! (root: it creates a network namespace with a veth pair; the workspace's binaries built
//! first: `cargo build --release --workspace --bins`).
//!
//! For 4, 16 and 64 emulated CiA 402 drives (`tandem-ecat-sim --devices drive,...` on `ecs`),
//! unmodified ethercrab 0.7.1 on `ecm` brings the segment to OP and times `SubDeviceGroup::tx_rx`
//! (the LRW of the whole process image and the AL status checks, as the node's exchange) once
//! per millisecond; beside it, in the same run, a raw AF_PACKET ping-pong between the same
//! interfaces: the same number of frames of the same sizes sent from `ecm` one after the
//! other (each back before the next goes, as ethercrab's `tx_rx` does), echoed by a process on
//! `ecs` that only sets the locally administered bit of the source MAC (as the emulator
//! does), timed until the last echo is back. Both peers run at SCHED_FIFO 40, as in
//! the system tests. Prints p50 / p99 / max of each and their ratio.
//!
//! The frame sizes of an exchange are computed from the process image (inferred from
//! ethercrab 0.7.1's `tx_rx`: one LRW PDU of the image, chunked to the frame's data size, and one
//! 2-byte AL status read per SubDevice, 12 bytes of PDU header and working counter each, 16
//! bytes of Ethernet and EtherCAT header per frame).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use ethercrab::std::tx_rx_task;
use ethercrab::{MainDevice, MainDeviceConfig, PduStorage, Timeouts};
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};
use tandem_ecat_sim::net::RawSocket;
use tandem_testkit::netns::{Background, VethNetns};

/// The data bytes of one frame (ethercrab's frame element, 28 bytes of headers besides).
const FRAME_DATA: usize = 1400;
/// Exchanges timed per segment (after 200 to warm up), one per millisecond.
const EXCHANGES: usize = 2000;
/// The segment sizes.
const DRIVES: [usize; 3] = [4, 16, 64];

static S4: PduStorage<16, { PduStorage::element_size(FRAME_DATA) }> = PduStorage::new();
static S16: PduStorage<16, { PduStorage::element_size(FRAME_DATA) }> = PduStorage::new();
static S64: PduStorage<16, { PduStorage::element_size(FRAME_DATA) }> = PduStorage::new();

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let Some(i) = args.iter().position(|a| a == "--echo") {
        return echo(&args[i + 1]);
    }
    if args.iter().any(|a| a == "--inner") {
        return inner();
    }
    // The parent: the namespace, then this program again inside it.
    let ns = VethNetns::create("tbe", "ecm", "ecs");
    let me = std::env::current_exe().unwrap();
    let status = ns
        .exec(Path::new("chrt"))
        .args(["-f", "40"])
        .arg(&me)
        .arg("--inner")
        .status()
        .expect("run the bench inside the namespace");
    assert!(status.success(), "the bench failed: {status}");
}

/// Inside the namespace: each segment size, then the table.
fn inner() {
    let mut rows = Vec::new();
    for (n, storage) in DRIVES.iter().zip([&S4, &S16, &S64]) {
        let devices = vec!["drive"; *n].join(",");
        let mut c = Command::new("chrt");
        c.args(["-f", "40"])
            .arg(tandem_testkit::workspace::bin("tandem-ecat-sim"))
            .args([
                "--interface",
                "ecs",
                "--devices",
                &devices,
                "--cycle-us",
                "1000",
            ]);
        let (sim, line) = Background::start(&mut c, Duration::from_secs(10), "tandem-ecat-sim");
        assert!(line.contains(&format!("{n} SubDevice(s)")), "{line}");
        let (pdi, ecat) = ethercrab_round_trips(storage, *n);
        drop(sim);
        let frames = frame_sizes(pdi, *n);
        let mut c = Command::new("chrt");
        c.args(["-f", "40"])
            .arg(std::env::current_exe().unwrap())
            .args(["--echo", "ecs"]);
        let (echo, line) = Background::start(&mut c, Duration::from_secs(10), "echo");
        assert!(line.contains("echo on ecs"), "{line}");
        let raw = raw_round_trips(&frames);
        drop(echo);
        rows.push((*n, pdi, frames, ecat, raw));
    }
    println!("EtherCAT PDI round trip over a veth pair, {EXCHANGES} exchanges at 1 kHz each (us)");
    println!(
        "{:>6} {:>6} {:>14} | {:>22} | {:>22} | {:>12}",
        "drives", "PDI B", "frames (B)", "ethercrab p50/p99/max", "raw p50/p99/max", "ratio 50/99"
    );
    for (n, pdi, frames, mut ecat, mut raw) in rows {
        let (e, r) = (stats(&mut ecat), stats(&mut raw));
        let sizes: Vec<String> = frames.iter().map(|f| f.to_string()).collect();
        println!(
            "{n:>6} {pdi:>6} {:>14} | {:>6.1} {:>6.1} {:>8.1} | {:>6.1} {:>6.1} {:>8.1} | {:>5.2} {:>5.2}",
            sizes.join("+"),
            e[0],
            e[1],
            e[2],
            r[0],
            r[1],
            r[2],
            e[0] / r[0],
            e[1] / r[1],
        );
    }
}

/// p50, p99, max in µs of round trips in ns.
fn stats(v: &mut [u64]) -> [f64; 3] {
    v.sort_unstable();
    let at = |q: f64| {
        let i = ((v.len() as f64 * q).ceil() as usize).clamp(1, v.len()) - 1;
        v[i] as f64 / 1000.0
    };
    [at(0.5), at(0.99), at(1.0)]
}

/// The Ethernet frame sizes of one exchange of a `pdi`-byte image on `n` SubDevices.
fn frame_sizes(pdi: usize, n: usize) -> Vec<usize> {
    let mut pdus: Vec<usize> = Vec::new();
    let mut left = pdi;
    while left > 0 {
        let chunk = left.min(FRAME_DATA - 12);
        pdus.push(12 + chunk);
        left -= chunk;
    }
    pdus.extend(std::iter::repeat_n(14, n));
    let mut frames = Vec::new();
    let mut cur = 0;
    for p in pdus {
        if cur + p > FRAME_DATA && cur > 0 {
            frames.push(cur);
            cur = 0;
        }
        cur += p;
    }
    frames.push(cur);
    frames.iter().map(|d| (d + 16).max(60)).collect()
}

/// ethercrab on `ecm` with `n` SubDevices to OP, then [`EXCHANGES`] timed `tx_rx`: the image
/// size and the round trips (ns).
fn ethercrab_round_trips(
    storage: &'static PduStorage<16, { PduStorage::element_size(FRAME_DATA) }>,
    n: usize,
) -> (usize, Vec<u64>) {
    let (tx, rx, pdu_loop) = storage.try_split().expect("split once");
    let task = tx_rx_task("ecm", tx, rx).expect("open ecm");
    std::thread::spawn(move || {
        // The task ends when the next segment's emulator answers frames it never sent.
        let _ = async_io::block_on(task);
    });
    let md = MainDevice::new(
        pdu_loop,
        Timeouts {
            pdu: Duration::from_millis(500),
            ..Timeouts::default()
        },
        MainDeviceConfig::default(),
    );
    async_io::block_on(async {
        let group = md
            .init_single_group::<64, 4096>(ethercrab::std::ethercat_now)
            .await
            .expect("init");
        assert_eq!(group.len(), n);
        let group = group.into_op(&md).await.expect("OP");
        let pdi: usize = group
            .iter(&md)
            .map(|sd| {
                let io = sd.io_raw();
                io.inputs().len() + io.outputs().len()
            })
            .sum();
        let mut trips = Vec::with_capacity(EXCHANGES);
        let mut next = Instant::now();
        for k in 0..EXCHANGES + 200 {
            next += Duration::from_millis(1);
            let t = Instant::now();
            group.tx_rx(&md).await.expect("tx_rx");
            if k >= 200 {
                trips.push(t.elapsed().as_nanos() as u64);
            }
            async_io::Timer::at(next).await;
        }
        (pdi, trips)
    })
}

/// [`EXCHANGES`] rounds of `frames` from `ecm` to the echo on `ecs` and back: round trips (ns).
fn raw_round_trips(frames: &[usize]) -> Vec<u64> {
    let socket = RawSocket::open("ecm").expect("open ecm");
    let mut out: Vec<Vec<u8>> = frames
        .iter()
        .map(|&len| {
            let mut f = vec![0u8; len];
            f[..6].copy_from_slice(&[0xFF; 6]);
            f[6..12].copy_from_slice(&[0x10; 6]);
            f[12..14].copy_from_slice(&0x88A4u16.to_be_bytes());
            f
        })
        .collect();
    let mut buf = vec![0u8; 9216];
    let mut trips = Vec::with_capacity(EXCHANGES);
    let mut next = Instant::now();
    for k in 0..EXCHANGES + 200 {
        next += Duration::from_millis(1);
        let t = Instant::now();
        // One frame after the other, each back before the next goes, as ethercrab's `tx_rx`
        // awaits each frame of an image before it sends the next.
        for (i, f) in out.iter_mut().enumerate() {
            // A tag in the payload, to match the echo.
            f[14] = i as u8;
            f[15] = k as u8;
            socket.send(f).expect("send");
            loop {
                let (len, outgoing) = socket.recv(&mut buf).expect("recv");
                if !outgoing
                    && len >= 16
                    && buf[6] & 0x02 != 0
                    && buf[14] == i as u8
                    && buf[15] == k as u8
                {
                    break;
                }
            }
        }
        if k >= 200 {
            trips.push(t.elapsed().as_nanos() as u64);
        }
        if let Some(wait) = next.checked_duration_since(Instant::now()) {
            std::thread::sleep(wait);
        }
    }
    trips
}

/// The echo on `interface`: every EtherCAT frame back with the locally administered bit of its
/// source MAC set, nothing else done to it.
fn echo(interface: &str) {
    let socket = RawSocket::open(interface).expect("open the echo's interface");
    eprintln!("echo on {interface}");
    let mut buf = vec![0u8; 9216];
    loop {
        let (len, outgoing) = socket.recv(&mut buf).expect("recv");
        if outgoing || len < 14 || buf[6] & 0x02 != 0 {
            continue;
        }
        buf[6] |= 0x02;
        socket.send(&buf[..len]).expect("send");
    }
}
