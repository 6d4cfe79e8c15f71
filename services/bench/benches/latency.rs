//! `tandem-bench-latency`: one-way leading-value latency between two processes, over raw
//! iceoryx2 and over tandem's own path, measured side by side in the same run.
//!
//! The parent process pings (pinned to CPU 0), a child started from this same binary with the
//! hidden `--role pong` answers (pinned to CPU 1). Both busy-wait on `receive()`. One round trip:
//! the ping sends sample `seq`, the pong answers with `seq`, the ping waits for it; one-way
//! latency is RTT / 2.
//!
//! - `raw`: services `a2b` / `b2a` (under a per-run prefix) with iceoryx2's default settings,
//!   payload [`LeadingValueSample`] sent with `send_copy`, nothing done with it on receipt.
//! - `tandem`: the leading-value services of leaders `ping` / `pong` of cell `bench`, opened with
//!   [`tipc::leading_values`] (history, safe overflow, the subscriber buffer of a node); the payload
//!   is built from a [`LeadingSample`] with [`LeadingValueSample::from_sample`] and, on receipt,
//!   converted back with `to_sample()`, pushed into a [`LeadingValueBuffer`] and read back at
//!   `t - D` (what a follower does) before answering.
//!
//! Modes: `busy` (round trips back to back) and `period` (one ping per 1 ms on an absolute grid
//! with [`rt::sleep_until`]; the pong still spins). Each round runs the four combinations, the
//! order of raw and tandem alternating from round to round; the table merges the rounds.

use clap::{Arg, ArgAction, Command};
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use std::process::{Child, ExitCode, Stdio};
use std::time::{Duration, Instant};
use tandem_bench::{cargo_bench_flag, fmt_us, median, Hist, Steal};
use tandem_motion::objects::leading::{LeadingSample, LeadingValue, LeadingValueBuffer};
use tandem_protocol::ipc as tipc;
use tandem_protocol::wire::LeadingValueSample;
use tandem_rt as rt;

/// The ping period of `period` mode (ns).
const PERIOD_NS: i64 = 1_000_000;
/// The sequence number that tells the pong to exit.
const STOP: u64 = u64::MAX;
/// The sequence number of the handshake probes.
const PROBE: u64 = u64::MAX - 1;
/// Leading-value delay D and tolerance of the follower work on the tandem path (ns): those of
/// a line cell on a real-time core (`config/line.toml` sizes them for a shared machine), D
/// 3 ms less half a cycle, so that `t - D` falls between two samples and the lookup
/// interpolates (the costlier case).
const DELAY_NS: i64 = 2_500_000;
const TOLERANCE_NS: i64 = 4_000_000;
/// The history a node gives the leading-value service of such a leader (delay 3 ms,
/// tolerance 4 ms, 1 ms cycle): `(D + tolerance) / cycle + 4`.
const HISTORY: usize = 11;
/// Round trips before each measurement that are not recorded.
const WARMUP: u64 = 2_000;
/// RTT histogram: 1 ns bins up to this, slower round trips kept as values.
const BINS: usize = 200_000;
/// A pong that hears nothing for this long gives up (the parent died).
const PONG_IDLE: Duration = Duration::from_secs(30);
/// A ping that gets no answer for this long gives up.
const PING_TIMEOUT: Duration = Duration::from_secs(3);

/// One end of a ping-pong.
trait End {
    /// Sends message `seq`.
    fn send(&mut self, seq: u64) -> Result<(), String>;
    /// One receive attempt: the sequence number of the sample received, after the path's
    /// receipt work.
    fn poll(&mut self) -> Result<Option<u64>, String>;
}

type Iox = iceoryx2::service::ipc::Service;
type Pub = Publisher<Iox, LeadingValueSample, ()>;
type Sub = Subscriber<Iox, LeadingValueSample, ()>;

/// Raw iceoryx2: default service settings, a fixed payload, only `seq` read on receipt.
struct Raw {
    _node: Node<Iox>,
    publisher: Pub,
    subscriber: Sub,
    payload: LeadingValueSample,
}

impl Raw {
    fn open(tag: &str, ping: bool) -> Result<Self, String> {
        set_log_level(LogLevel::Error);
        let node = NodeBuilder::new()
            .create::<Iox>()
            .map_err(|e| format!("iceoryx2 node: {e}"))?;
        let open = |dir: &str| {
            let name = format!("tandem-bench/{tag}/{dir}");
            let service_name =
                ServiceName::new(&name).map_err(|e| format!("service name {name}: {e}"))?;
            node.service_builder(&service_name)
                .publish_subscribe::<LeadingValueSample>()
                .open_or_create()
                .map_err(|e| format!("service {name}: {e}"))
        };
        let (a2b, b2a) = (open("a2b")?, open("b2a")?);
        let (out, inp) = if ping { (&a2b, &b2a) } else { (&b2a, &a2b) };
        let publisher = out
            .publisher_builder()
            .create()
            .map_err(|e| format!("publisher: {e}"))?;
        let subscriber = inp
            .subscriber_builder()
            .create()
            .map_err(|e| format!("subscriber: {e}"))?;
        let payload = LeadingValueSample::from_sample(u32::from(!ping), &leader_sample(0, 0.0));
        Ok(Self {
            _node: node,
            publisher,
            subscriber,
            payload,
        })
    }
}

impl End for Raw {
    #[inline]
    fn send(&mut self, seq: u64) -> Result<(), String> {
        self.payload.seq = seq;
        self.publisher
            .send_copy(self.payload)
            .map(|_| ())
            .map_err(|e| format!("send: {e}"))
    }

    #[inline]
    fn poll(&mut self) -> Result<Option<u64>, String> {
        match self.subscriber.receive() {
            Ok(Some(s)) => Ok(Some(s.payload().seq)),
            Ok(None) => Ok(None),
            Err(e) => Err(format!("receive: {e}")),
        }
    }
}

/// The sample a leader sends for message `seq`: time `seq` cycles, position `p`.
fn leader_sample(seq: u64, p: f64) -> LeadingSample {
    LeadingSample {
        t_ns: (seq as i64).wrapping_mul(PERIOD_NS),
        seq,
        p,
        v: 1000.0,
        a: 0.0,
        modulo: None,
        valid: true,
    }
}

/// tandem's path: the leading-value services as a node opens them, the wire conversion both
/// ways and a follower's buffer and lookup on every receipt.
struct Tandem {
    _node: tipc::IpcNode,
    publisher: Pub,
    subscriber: Sub,
    leader: u32,
    buffer: Box<LeadingValueBuffer<256>>,
    /// The value the follower work read last; the answer carries it on.
    value: LeadingValue,
    lookups_missing: u64,
}

impl Tandem {
    fn open(ping: bool) -> Result<Self, String> {
        let me = if ping { "ping" } else { "pong" };
        let node = tipc::node(&format!("tandem/bench/{me}"), "bench").map_err(|e| e.to_string())?;
        let lv = |leader: &str| {
            tipc::leading_values(&node, "bench", leader, false, HISTORY).map_err(|e| e.to_string())
        };
        let (ping_lv, pong_lv) = (lv("ping")?, lv("pong")?);
        let (out, inp) = if ping {
            (&ping_lv, &pong_lv)
        } else {
            (&pong_lv, &ping_lv)
        };
        // As tandem-node creates its ports.
        let publisher = out
            .publisher_builder()
            .create()
            .map_err(|e| format!("publisher: {e}"))?;
        let subscriber = inp
            .subscriber_builder()
            .buffer_size(HISTORY)
            .create()
            .map_err(|e| format!("subscriber: {e}"))?;
        Ok(Self {
            _node: node,
            publisher,
            subscriber,
            leader: u32::from(!ping),
            buffer: Box::default(),
            value: LeadingValue {
                p: 0.0,
                v: 0.0,
                a: 0.0,
                modulo: None,
            },
            lookups_missing: 0,
        })
    }
}

impl End for Tandem {
    #[inline]
    fn send(&mut self, seq: u64) -> Result<(), String> {
        let mut s = leader_sample(seq, self.value.p + 1.0);
        s.v = self.value.v;
        let wire = LeadingValueSample::from_sample(self.leader, &s);
        self.publisher
            .send_copy(wire)
            .map(|_| ())
            .map_err(|e| format!("send: {e}"))
    }

    #[inline]
    fn poll(&mut self) -> Result<Option<u64>, String> {
        let s = match self.subscriber.receive() {
            Ok(Some(sample)) => sample.payload().to_sample(),
            Ok(None) => return Ok(None),
            Err(e) => return Err(format!("receive: {e}")),
        };
        // Probes and repeats come with old times: refused, as a node refuses them.
        let _ = self.buffer.push(s);
        match self.buffer.at(s.t_ns - DELAY_NS, TOLERANCE_NS).value() {
            Some(v) => self.value = v,
            None => self.lookups_missing += 1,
        }
        Ok(Some(s.seq))
    }
}

/// One-way (RTT / 2) quantile of `h` in µs.
fn one_way_us(h: &Hist, q: f64) -> f64 {
    h.quantile(q) as f64 / 2000.0
}

#[derive(Copy, Clone, Debug, PartialEq, Eq)]
enum Path {
    Raw,
    Tandem,
}

impl Path {
    fn name(self) -> &'static str {
        match self {
            Path::Raw => "raw",
            Path::Tandem => "tandem",
        }
    }
}

#[derive(Copy, Clone, Debug, PartialEq, Eq)]
enum Mode {
    Busy,
    Period,
}

impl Mode {
    fn name(self) -> &'static str {
        match self {
            Mode::Busy => "busy",
            Mode::Period => "period",
        }
    }
}

/// What one measurement gave.
#[derive(Debug)]
struct Measured {
    hist: Hist,
    /// Wall time of the measured loop (ns): in busy mode, total / (2 n) is iceoryx2's own
    /// benchmark figure.
    total_ns: u64,
    /// Period mode: grid slots the ping woke up for more than a period late.
    late_wakeups: u64,
}

/// Waits for the answer to `seq`, dropping others (late answers to probes).
#[inline]
fn await_answer<E: End>(e: &mut E, seq: u64, sent: Instant) -> Result<(), String> {
    let mut spins = 0u32;
    loop {
        match e.poll()? {
            Some(s) if s == seq => return Ok(()),
            Some(_) => {}
            None => {
                spins = spins.wrapping_add(1);
                if spins % 16_384 == 0 && sent.elapsed() > PING_TIMEOUT {
                    return Err(format!(
                        "no answer to message {seq} within {PING_TIMEOUT:?}: the pong stopped"
                    ));
                }
            }
        }
    }
}

/// Probes until the pong answers (its ports connect to ours when it starts).
fn handshake<E: End>(e: &mut E) -> Result<(), String> {
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        e.send(PROBE)?;
        let sent = Instant::now();
        while sent.elapsed() < Duration::from_millis(20) {
            if e.poll()? == Some(PROBE) {
                return Ok(());
            }
        }
        if Instant::now() > deadline {
            return Err("the pong did not answer within 10 s".into());
        }
    }
}

fn ping<E: End>(e: &mut E, mode: Mode, n: u64) -> Result<Measured, String> {
    handshake(e)?;
    let mut seq = 1u64;
    for _ in 0..WARMUP {
        let t0 = Instant::now();
        e.send(seq)?;
        await_answer(e, seq, t0)?;
        seq += 1;
    }
    let mut hist = Hist::new(BINS);
    let mut late_wakeups = 0;
    let start = Instant::now();
    match mode {
        Mode::Busy => {
            for _ in 0..n {
                let t0 = Instant::now();
                e.send(seq)?;
                await_answer(e, seq, t0)?;
                let rtt = t0.elapsed();
                hist.record(u64::try_from(rtt.as_nanos()).unwrap_or(u64::MAX));
                seq += 1;
            }
        }
        Mode::Period => {
            let grid = (rt::now_ns() / PERIOD_NS + 2) * PERIOD_NS;
            for k in 0..n as i64 {
                let slot = grid + k * PERIOD_NS;
                rt::sleep_until(slot);
                if rt::now_ns() > slot + PERIOD_NS {
                    late_wakeups += 1;
                }
                let t0 = Instant::now();
                e.send(seq)?;
                await_answer(e, seq, t0)?;
                let rtt = t0.elapsed();
                hist.record(u64::try_from(rtt.as_nanos()).unwrap_or(u64::MAX));
                seq += 1;
            }
        }
    }
    let total_ns = u64::try_from(start.elapsed().as_nanos()).unwrap_or(u64::MAX);
    // The pong exits on STOP; a second one in case the first overflowed its buffer.
    e.send(STOP)?;
    e.send(STOP)?;
    Ok(Measured {
        hist,
        total_ns,
        late_wakeups,
    })
}

fn pong<E: End>(e: &mut E) -> Result<(), String> {
    // The clock is read only after a quiet stretch, never on the answering path.
    let mut quiet_since: Option<Instant> = None;
    let mut spins = 0u32;
    loop {
        match e.poll()? {
            Some(STOP) => return Ok(()),
            Some(seq) => {
                e.send(seq)?;
                spins = 0;
                quiet_since = None;
            }
            None => {
                spins = spins.wrapping_add(1);
                if spins % 65_536 == 0 {
                    match quiet_since {
                        None => quiet_since = Some(Instant::now()),
                        Some(t) if t.elapsed() > PONG_IDLE => {
                            return Err(format!("no message for {PONG_IDLE:?}; exiting"));
                        }
                        Some(_) => {}
                    }
                }
            }
        }
    }
}

/// The child process; killed if still running when dropped.
struct PongProcess(Child);

impl Drop for PongProcess {
    fn drop(&mut self) {
        let deadline = Instant::now() + Duration::from_secs(5);
        loop {
            match self.0.try_wait() {
                Ok(Some(_)) => return,
                Ok(None) if Instant::now() < deadline => {
                    std::thread::sleep(Duration::from_millis(5));
                }
                _ => {
                    // Cleanup after the grace time: a child that is gone already is fine.
                    let _ = self.0.kill();
                    // Reaps the killed child; an error means it is gone already.
                    let _ = self.0.wait();
                    return;
                }
            }
        }
    }
}

impl PongProcess {
    fn spawn(path: Path, tag: &str) -> Result<Self, String> {
        let exe = std::env::current_exe().map_err(|e| format!("own executable: {e}"))?;
        std::process::Command::new(exe)
            .args(["--role", "pong", "--path", path.name(), "--tag", tag])
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::inherit())
            .spawn()
            .map(PongProcess)
            .map_err(|e| format!("cannot start the pong process: {e}"))
    }

    /// Waits for the pong to exit after STOP; its exit status.
    fn finish(mut self) -> Result<(), String> {
        let deadline = Instant::now() + Duration::from_secs(5);
        loop {
            match self.0.try_wait() {
                Ok(Some(s)) if s.success() => return Ok(()),
                Ok(Some(s)) => return Err(format!("the pong process failed ({s})")),
                Ok(None) if Instant::now() < deadline => {
                    std::thread::sleep(Duration::from_millis(2));
                }
                Ok(None) => return Err("the pong process did not stop".into()),
                Err(e) => return Err(format!("waiting for the pong process: {e}")),
            }
        }
    }
}

/// One measurement: creates the services, starts the pong, pings.
fn measure(path: Path, mode: Mode, n: u64, tag: &str) -> Result<Measured, String> {
    // Our ports exist before the pong opens the services, so both never race to create them.
    let m = match path {
        Path::Raw => {
            let tag = format!("{tag}/{}", mode.name());
            let mut end = Raw::open(&tag, true)?;
            let pong = PongProcess::spawn(path, &tag)?;
            let m = ping(&mut end, mode, n)?;
            pong.finish()?;
            m
        }
        Path::Tandem => {
            let mut end = Tandem::open(true)?;
            let pong = PongProcess::spawn(path, tag)?;
            let m = ping(&mut end, mode, n)?;
            pong.finish()?;
            if end.lookups_missing > WARMUP + 1 {
                eprintln!(
                    "tandem-bench-latency: note: {} follower lookups found no value",
                    end.lookups_missing
                );
            }
            m
        }
    };
    Ok(m)
}

fn run_pong(path: &str, tag: &str) -> Result<(), String> {
    if let Err(w) = rt::pin_to_cpu(1) {
        eprintln!("tandem-bench-latency pong: warning: {w}; running unpinned");
    }
    match path {
        "raw" => pong(&mut Raw::open(tag, false)?),
        "tandem" => pong(&mut Tandem::open(false)?),
        other => Err(format!("unknown path `{other}`")),
    }
}

/// The cache-line floor: one-way latency of an atomic ping-pong between this thread (CPU 0)
/// and a thread on CPU 1, total / (2 n) in µs. Where the hypervisor places the two vCPUs
/// (SMT siblings or not) moves every figure of this bench; this shows which it was.
fn cache_line_floor(n: u64) -> f64 {
    use std::sync::atomic::{AtomicU64, Ordering};
    let flag = AtomicU64::new(0);
    let took = std::thread::scope(|s| {
        s.spawn(|| {
            // Pinning is best effort; the report states the CPU the run had.
            let _ = rt::pin_to_cpu(1);
            for i in 0..n {
                while flag.load(Ordering::Acquire) != 2 * i + 1 {
                    std::hint::spin_loop();
                }
                flag.store(2 * i + 2, Ordering::Release);
            }
        });
        let start = Instant::now();
        for i in 0..n {
            flag.store(2 * i + 1, Ordering::Release);
            while flag.load(Ordering::Acquire) != 2 * i + 2 {
                std::hint::spin_loop();
            }
        }
        start.elapsed()
    });
    took.as_secs_f64() * 1e6 / (2.0 * n as f64)
}

fn main() -> ExitCode {
    let m = Command::new("tandem-bench-latency")
        .about(
            "One-way leading-value latency node to node: raw iceoryx2 and tandem's path, \
             back to back and at a 1 ms period, in the same run",
        )
        .arg(
            Arg::new("iterations")
                .long("iterations")
                .value_parser(clap::value_parser!(u64).range(1..))
                .default_value("200000")
                .help("Round trips per busy measurement"),
        )
        .arg(
            Arg::new("period-iterations")
                .long("period-iterations")
                .value_parser(clap::value_parser!(u64).range(1..))
                .default_value("5000")
                .help("Round trips per 1 ms-period measurement"),
        )
        .arg(
            Arg::new("rounds")
                .long("rounds")
                .value_parser(clap::value_parser!(u64).range(1..))
                .default_value("3")
                .help("Rounds of the four measurements (raw/tandem order alternates)"),
        )
        .arg(
            Arg::new("quick")
                .long("quick")
                .action(ArgAction::SetTrue)
                .help("10x fewer round trips and one round (a smoke test)"),
        )
        .arg(Arg::new("role").long("role").hide(true))
        .arg(Arg::new("path").long("path").hide(true))
        .arg(Arg::new("tag").long("tag").hide(true))
        .arg(cargo_bench_flag())
        .get_matches();

    if m.get_one::<String>("role").map(String::as_str) == Some("pong") {
        let path = m.get_one::<String>("path").map_or("", String::as_str);
        let tag = m.get_one::<String>("tag").map_or("", String::as_str);
        return match run_pong(path, tag) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("tandem-bench-latency pong: error: {e}");
                ExitCode::FAILURE
            }
        };
    }
    let (busy_n, period_n, rounds) = tandem_bench::ping_pong_sizes(&m, 200_000);
    match run(busy_n.max(1), period_n.max(1), rounds) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("tandem-bench-latency: error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(busy_n: u64, period_n: u64, rounds: u64) -> Result<(), String> {
    let cleaned = tipc::cleanup_dead_nodes("bench");
    if cleaned > 0 {
        eprintln!("tandem-bench-latency: removed the resources of {cleaned} crashed process(es)");
    }
    if let Err(w) = rt::pin_to_cpu(0) {
        eprintln!("tandem-bench-latency: warning: {w}; running unpinned");
    }
    // As tandem-node's cyclic thread: absolute sleeps end when asked.
    rt::no_timer_slack();
    let tag = std::process::id().to_string();
    let rows = [
        (Path::Raw, Mode::Busy),
        (Path::Tandem, Mode::Busy),
        (Path::Raw, Mode::Period),
        (Path::Tandem, Mode::Period),
    ];
    let mut merged: Vec<Option<Measured>> = rows.iter().map(|_| None).collect();
    // Per round: p50 of each row (µs).
    let mut p50s: Vec<Vec<f64>> = rows.iter().map(|_| Vec::new()).collect();
    let started = Instant::now();
    let steal0 = Steal::start();
    let mut floors = Vec::new();
    for r in 0..rounds {
        floors.push(cache_line_floor(200_000));
        for mode in [Mode::Busy, Mode::Period] {
            let order = if r % 2 == 0 {
                [Path::Raw, Path::Tandem]
            } else {
                [Path::Tandem, Path::Raw]
            };
            for path in order {
                let n = if mode == Mode::Busy { busy_n } else { period_n };
                let st = Steal::start();
                let x = measure(path, mode, n, &tag)
                    .map_err(|e| format!("{} {}: {e}", path.name(), mode.name()))?;
                let st = st.percent();
                let i = rows
                    .iter()
                    .position(|row| *row == (path, mode))
                    .unwrap_or(0);
                eprintln!(
                    "round {}/{rounds}: {:<6} {:<6} n {:>7}: p50 {} µs, p99 {} µs, steal {st:.1} %",
                    r + 1,
                    path.name(),
                    mode.name(),
                    n,
                    fmt_us(one_way_us(&x.hist, 0.5)),
                    fmt_us(one_way_us(&x.hist, 0.99))
                );
                p50s[i].push(one_way_us(&x.hist, 0.5));
                match &mut merged[i] {
                    Some(all) => {
                        all.hist.merge(&x.hist);
                        all.total_ns += x.total_ns;
                        all.late_wakeups += x.late_wakeups;
                    }
                    slot @ None => *slot = Some(x),
                }
            }
        }
    }
    let elapsed = started.elapsed();
    let steal = steal0.percent();

    println!();
    println!(
        "tandem-bench-latency: one-way latency = RTT/2 in µs; ping on CPU 0, pong (a child \
         process) on CPU 1, both busy-wait on receive(); payload LeadingValueSample ({} bytes); \
         {rounds} round(s) merged",
        core::mem::size_of::<LeadingValueSample>()
    );
    println!(
        "{:<7} {:<7} {:>8} {:>7} {:>7} {:>7} {:>8} {:>7} {:>9} {:>11}",
        "path", "mode", "n", "p50", "p99", "p99.9", "max", "mean", "total/2n", "tandem/raw"
    );
    for (i, (path, mode)) in rows.iter().enumerate() {
        let Some(x) = &merged[i] else { continue };
        let h = &x.hist;
        let total = if *mode == Mode::Busy && h.count() > 0 {
            fmt_us(x.total_ns as f64 / h.count() as f64 / 2000.0)
        } else {
            "-".into()
        };
        let ratio = if *path == Path::Tandem {
            let raw = rows
                .iter()
                .position(|row| *row == (Path::Raw, *mode))
                .and_then(|j| merged[j].as_ref());
            raw.map_or("-".into(), |r| {
                format!("{:.2}", one_way_us(h, 0.5) / one_way_us(&r.hist, 0.5))
            })
        } else {
            String::new()
        };
        println!(
            "{:<7} {:<7} {:>8} {:>7} {:>7} {:>7} {:>8} {:>7} {:>9} {:>11}",
            path.name(),
            mode.name(),
            h.count(),
            fmt_us(one_way_us(h, 0.5)),
            fmt_us(one_way_us(h, 0.99)),
            fmt_us(one_way_us(h, 0.999)),
            fmt_us(one_way_us(h, 1.0)),
            fmt_us(h.mean() / 2000.0),
            total,
            ratio
        );
    }
    if rounds > 1 {
        for mode in [Mode::Busy, Mode::Period] {
            let col = |p: Path| {
                rows.iter()
                    .position(|row| *row == (p, mode))
                    .map(|i| p50s[i].clone())
                    .unwrap_or_default()
            };
            let (raw, tandem) = (col(Path::Raw), col(Path::Tandem));
            let ratios: Vec<f64> = raw
                .iter()
                .zip(&tandem)
                .map(|(r, t)| if *r > 0.0 { t / r } else { 0.0 })
                .collect();
            let list = |v: &[f64]| v.iter().map(|x| fmt_us(*x)).collect::<Vec<_>>().join(" ");
            println!(
                "{:<6} p50 per round: raw {} | tandem {} | ratio {} (median of rounds: raw {}, \
                 tandem {}, ratio {:.2})",
                mode.name(),
                list(&raw),
                list(&tandem),
                ratios
                    .iter()
                    .map(|x| format!("{x:.2}"))
                    .collect::<Vec<_>>()
                    .join(" "),
                fmt_us(median(raw.clone())),
                fmt_us(median(tandem.clone())),
                median(ratios.clone())
            );
        }
    }
    println!(
        "cache-line floor (atomic ping-pong, CPU 0 <-> 1) per round: {} µs one-way",
        floors
            .iter()
            .map(|x| format!("{x:.3}"))
            .collect::<Vec<_>>()
            .join(" ")
    );
    let late: u64 = rows
        .iter()
        .enumerate()
        .filter(|(_, (_, m))| *m == Mode::Period)
        .filter_map(|(i, _)| merged[i].as_ref().map(|x| x.late_wakeups))
        .sum();
    println!(
        "mean = sum of RTTs / 2n; total/2n = wall time of the busy loop / 2n (iceoryx2's \
         benchmark figure); ratio at p50. Period wake-ups more than 1 ms late: {late}. \
         Hypervisor steal over the run: {steal:.1} % of both CPUs. Took {:.1} s.",
        elapsed.as_secs_f64()
    );
    Ok(())
}
