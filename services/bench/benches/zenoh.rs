//! `tandem-bench-zenoh`: leading-value latency between two hosts, over raw Zenoh and over
//! tandem's whole path, measured side by side in the same run.
//!
//! The bench creates two network namespaces joined by a veth pair (host A `10.x.0.1`, host B
//! `10.x.0.2`) and removes them at the end, on every exit path. Every process it starts runs
//! in one of them through `ip netns exec` and is stopped at the end. One round trip: the ping
//! (in A) sends message `seq`, the pong (in B) answers with `seq`, the ping waits for it;
//! one-way latency is RTT / 2. Both ends busy-poll their receiver, with `sched_yield` between
//! empty polls unless `--spin pure` (see [`idle`]).
//!
//! - `raw`: a Zenoh ping-pong of the 64-byte leading-value payload
//!   ([`json::encode_leading_value`]) with the gateway's QoS (`Priority::RealTime`, express,
//!   `CongestionControl::Block`): peer mode, scouting off, the pong listening on
//!   `tcp/<addr B>:7447`, the ping connecting to it.
//! - `tandem`: node → gateway → Zenoh → gateway → node and back. A generated two-host cell has
//!   leader `ping` (node `na`, host `hA`) followed on `hB` and leader `pong` (node `nb`, host
//!   `hB`) followed on `hA`; the real `tandem-gateway` runs in each namespace (listening on
//!   port 7557). The ping
//!   impersonates node `na`: it publishes a [`LeadingValueSample`] into host A's iceoryx2
//!   service of `ping` and notifies `na`'s `published` event, as tandem-node does each cycle.
//!   The pong impersonates `nb`: it reads the sample from host B's service of `ping` (where
//!   gateway B put it), publishes its `pong` sample and notifies `nb`'s event; gateway B sends
//!   it back and the ping reads it from host A's service of `pong`.
//!
//! Modes: `busy` (round trips back to back) and `period` (one ping per 1 ms on an absolute grid
//! with [`rt::sleep_until`]; the pong still spins). Each round measures both paths (the order
//! alternates from round to round), each path with one ping and one pong process doing busy
//! then period; the gateways run for the whole bench. A round trip not answered within
//! 100 ms is counted as lost (Zenoh drops on congestion).

use clap::{Arg, ArgAction, Command};
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use std::io::{BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ExitCode, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};
use tandem_bench::{
    cargo_bench_flag, fmt_us, machine_ticks, median, process_ticks, quantile, sibling_binary, Steal,
};
use tandem_protocol::ipc::{self, IpcNode};
use tandem_protocol::json;
use tandem_protocol::names;
use tandem_protocol::wire::{LeadingValueSample, LV_VALID};
use tandem_rt as rt;
use zenoh::handlers::FifoChannelHandler;
use zenoh::qos::{CongestionControl, Priority};
use zenoh::sample::{Locality, Sample};
use zenoh::Wait;

/// The ping period of `period` mode (ns).
const PERIOD_NS: i64 = 1_000_000;
/// Round trips after the first answer that are not recorded.
const WARMUP: u64 = 1_000;
/// The first round trip must succeed within this (the gateways connect).
const CONNECT_TIMEOUT: Duration = Duration::from_secs(20);
/// A round trip not answered within this is lost.
const ANSWER_TIMEOUT: Duration = Duration::from_millis(100);
/// So many lost round trips in a row fail the bench.
const MAX_LOST_IN_A_ROW: u32 = 50;
/// A pong that hears nothing for this long gives up (the bench died).
const PONG_IDLE: Duration = Duration::from_secs(60);
/// A pong spins this long after its last message, then polls every 200 µs (so that, while
/// the gateways start, two spinning processes do not take both CPUs).
const PONG_SPIN: Duration = Duration::from_millis(50);
/// The raw pong's Zenoh port.
const RAW_PORT: u16 = 7447;
/// The gateways' Zenoh port (the cell's `[[hosts]] listen`).
const GATEWAY_PORT: u16 = 7557;
/// Message numbers: the round in the top 16 bits, so that a pong never answers (or stops on)
/// an earlier round's sample kept in an iceoryx2 history.
const ROUND_SHIFT: u32 = 48;
const LOW_MASK: u64 = (1 << ROUND_SHIFT) - 1;
/// Handshake probes have this bit.
const PROBE_BIT: u64 = 1 << 47;
/// The message that stops the pong (low bits all set).
const STOP_LOW: u64 = LOW_MASK;
/// Leading-value delays D of the sync-error table (ms); the follower cycle is 1 ms.
const DELAYS_MS: [i64; 5] = [1, 2, 5, 10, 20];
/// SIGTERM on Linux.
const SIGTERM: i32 = 15;

type Iox = iceoryx2::service::ipc::Service;

/// `--spin pure`: receivers spin without ever giving up the CPU.
static PURE_SPIN: AtomicBool = AtomicBool::new(false);

/// What a receiver does between two empty polls. By default it yields: with two CPUs, two
/// receivers that never yield leave Zenoh's I/O threads and the gateways' threads to wait for
/// the scheduler to preempt them (up to a time slice, milliseconds), which measures the
/// scheduler rather than the path. `sched_yield` lets a woken thread run at once and costs
/// about a microsecond.
#[inline]
fn idle() {
    if PURE_SPIN.load(Ordering::Relaxed) {
        std::hint::spin_loop();
    } else {
        std::thread::yield_now();
    }
}

/// One end of a ping-pong.
trait End {
    /// Sends message `seq`.
    fn send(&mut self, seq: u64) -> Result<(), String>;
    /// One receive attempt: the message number received.
    fn poll(&mut self) -> Result<Option<u64>, String>;
}

/// A leading value of leader `leader` for message `seq`, valid, with finite values.
fn sample(leader: u32, seq: u64) -> LeadingValueSample {
    LeadingValueSample {
        t_ns: rt::now_ns(),
        seq,
        p: (seq & 0xFFFF) as f64 * 1e-3,
        v: 1.0,
        a: 0.0,
        modulo_start: 0.0,
        modulo_length: 0.0,
        status: LV_VALID,
        leader,
    }
}

/// Raw Zenoh: one session, a publisher with the gateway's QoS, a subscriber polled with
/// `try_recv`.
struct RawEnd {
    publisher: zenoh::pubsub::Publisher<'static>,
    subscriber: zenoh::pubsub::Subscriber<FifoChannelHandler<Sample>>,
    _session: zenoh::Session,
    leader: u32,
}

impl RawEnd {
    fn open(addr: &str, tag: &str, ping: bool) -> Result<Self, String> {
        let mut c = zenoh::Config::default();
        let endpoint = serde_json::to_string(&[format!("tcp/{addr}:{RAW_PORT}")])
            .map_err(|e| format!("endpoint: {e}"))?;
        let settings = [
            ("mode", "\"peer\"".to_string()),
            (
                if ping {
                    "connect/endpoints"
                } else {
                    "listen/endpoints"
                },
                endpoint,
            ),
            ("scouting/multicast/enabled", "false".into()),
            ("scouting/gossip/enabled", "false".into()),
        ];
        for (k, v) in settings {
            c.insert_json5(k, &v)
                .map_err(|e| format!("zenoh config {k} = {v}: {e}"))?;
        }
        let session = zenoh::open(c)
            .wait()
            .map_err(|e| format!("opening the Zenoh session: {e}"))?;
        let (out, inp) = if ping {
            ("ping", "pong")
        } else {
            ("pong", "ping")
        };
        let key = format!("tandem-bench/{tag}/{out}");
        let publisher = session
            .declare_publisher(key.clone())
            .priority(Priority::RealTime)
            .express(true)
            .congestion_control(CongestionControl::Block)
            .allowed_destination(Locality::Remote)
            .wait()
            .map_err(|e| format!("publisher {key}: {e}"))?;
        let key = format!("tandem-bench/{tag}/{inp}");
        let subscriber = session
            .declare_subscriber(key.clone())
            .wait()
            .map_err(|e| format!("subscriber {key}: {e}"))?;
        Ok(Self {
            publisher,
            subscriber,
            _session: session,
            leader: u32::from(!ping),
        })
    }
}

impl End for RawEnd {
    fn send(&mut self, seq: u64) -> Result<(), String> {
        self.publisher
            .put(json::encode_leading_value(&sample(self.leader, seq)))
            .wait()
            .map_err(|e| format!("put: {e}"))
    }

    fn poll(&mut self) -> Result<Option<u64>, String> {
        match self.subscriber.try_recv() {
            Ok(Some(s)) => json::decode_leading_value(&s.payload().to_bytes())
                .map(|x| Some(x.seq))
                .map_err(|e| format!("a malformed answer: {e}")),
            Ok(None) => Ok(None),
            Err(e) => Err(format!("receive: {e}")),
        }
    }
}

/// The iceoryx2 history of leader `l`'s service, as the gateway and tandem-node open it.
/// tandem's node side: node `na` (ping) or `nb` (pong) of the generated cell, publishing its
/// leader's samples and notifying its `published` event, reading the other leader's samples.
struct TandemEnd {
    publisher: Publisher<Iox, LeadingValueSample, ()>,
    subscriber: Subscriber<Iox, LeadingValueSample, ()>,
    notifier: Notifier<Iox>,
    _node: IpcNode,
    leader: u32,
}

impl TandemEnd {
    fn open(cell_path: &Path, ping: bool) -> Result<Self, String> {
        let cell = tandem_config::load(cell_path).map_err(|e| e.to_string())?;
        let (mine, theirs, me) = if ping {
            ("ping", "pong", "na")
        } else {
            ("pong", "ping", "nb")
        };
        let index = |name: &str| {
            cell.leader_named(name)
                .ok_or_else(|| format!("the cell has no leader `{name}`"))
        };
        let (l_mine, l_theirs) = (index(mine)?, index(theirs)?);
        let n = cell
            .node(me)
            .ok_or_else(|| format!("the cell has no node `{me}`"))?;
        let host = &cell.hosts[cell.nodes[n].host];
        let node = ipc::node(&names::node(&cell.name, me), host).map_err(|e| e.to_string())?;
        let out = ipc::leading_values(&node, &cell.name, mine, false, cell.leading_history(l_mine))
            .map_err(|e| e.to_string())?;
        let inp = ipc::leading_values(
            &node,
            &cell.name,
            theirs,
            false,
            cell.leading_history(l_theirs),
        )
        .map_err(|e| e.to_string())?;
        // As tandem-node creates its ports.
        let publisher = out
            .publisher_builder()
            .create()
            .map_err(|e| format!("publisher for {mine}: {e}"))?;
        let subscriber = inp
            .subscriber_builder()
            .buffer_size(cell.leading_history(l_theirs))
            .create()
            .map_err(|e| format!("subscriber for {theirs}: {e}"))?;
        let notifier = ipc::published(&node, &cell.name, me)
            .map_err(|e| e.to_string())?
            .notifier_builder()
            .create()
            .map_err(|e| format!("published notifier: {e}"))?;
        Ok(Self {
            publisher,
            subscriber,
            notifier,
            _node: node,
            leader: cell.leader_id(l_mine),
        })
    }
}

impl End for TandemEnd {
    fn send(&mut self, seq: u64) -> Result<(), String> {
        self.publisher
            .send_copy(sample(self.leader, seq))
            .map_err(|e| format!("send: {e}"))?;
        self.notifier
            .notify()
            .map(|_| ())
            .map_err(|e| format!("notify: {e}"))
    }

    fn poll(&mut self) -> Result<Option<u64>, String> {
        match self.subscriber.receive() {
            Ok(Some(s)) => Ok(Some(s.payload().seq)),
            Ok(None) => Ok(None),
            Err(e) => Err(format!("receive: {e}")),
        }
    }
}

/// Waits for the answer to `seq` (dropping others): its RTT in ns, or `None` after
/// [`ANSWER_TIMEOUT`].
#[inline]
fn await_answer<E: End>(e: &mut E, seq: u64, t0: Instant) -> Result<Option<u64>, String> {
    let mut spins = 0u32;
    loop {
        match e.poll()? {
            Some(s) if s == seq => {
                return Ok(Some(
                    u64::try_from(t0.elapsed().as_nanos()).unwrap_or(u64::MAX),
                ))
            }
            Some(_) => {}
            None => {
                spins = spins.wrapping_add(1);
                if spins % 1024 == 0 && t0.elapsed() > ANSWER_TIMEOUT {
                    return Ok(None);
                }
                idle();
            }
        }
    }
}

/// Probes until the first round trip succeeds, within [`CONNECT_TIMEOUT`]; the time it took.
fn handshake<E: End>(e: &mut E, base: u64, what: &str) -> Result<Duration, String> {
    let start = Instant::now();
    for j in 0.. {
        let seq = base | PROBE_BIT | j;
        e.send(seq)?;
        let sent = Instant::now();
        while sent.elapsed() < Duration::from_millis(100) {
            match e.poll()? {
                Some(s) if s == seq => return Ok(start.elapsed()),
                Some(_) => {}
                None => std::thread::sleep(Duration::from_millis(1)),
            }
        }
        if start.elapsed() > CONNECT_TIMEOUT {
            break;
        }
    }
    Err(format!(
        "no round trip within {CONNECT_TIMEOUT:?}: {what} did not connect"
    ))
}

/// What one mode of a ping gave.
#[derive(Debug, Default, Clone)]
struct Series {
    /// RTTs (ns) of the answered round trips.
    rtt: Vec<u64>,
    /// Round trips not answered within [`ANSWER_TIMEOUT`].
    lost: u64,
    /// Period mode: grid slots woken up for more than a period late.
    late: u64,
}

impl Series {
    fn to_line(&self, mode: &str) -> String {
        let mut s = String::with_capacity(16 + 8 * self.rtt.len());
        s.push_str(&format!("{mode} {} {}", self.lost, self.late));
        for r in &self.rtt {
            s.push(' ');
            s.push_str(&r.to_string());
        }
        s
    }

    fn from_line(line: &str) -> Option<(String, Series)> {
        let mut f = line.split_whitespace();
        let mode = f.next()?.to_string();
        let lost = f.next()?.parse().ok()?;
        let late = f.next()?.parse().ok()?;
        let rtt = f.map(|x| x.parse().ok()).collect::<Option<Vec<u64>>>()?;
        Some((mode, Series { rtt, lost, late }))
    }
}

/// Records one round trip; fails after [`MAX_LOST_IN_A_ROW`] lost ones in a row.
fn record(s: &mut Series, rtt: Option<u64>, lost_in_a_row: &mut u32) -> Result<(), String> {
    match rtt {
        Some(r) => {
            s.rtt.push(r);
            *lost_in_a_row = 0;
        }
        None => {
            s.lost += 1;
            *lost_in_a_row += 1;
            if *lost_in_a_row >= MAX_LOST_IN_A_ROW {
                return Err(format!(
                    "{MAX_LOST_IN_A_ROW} round trips in a row were not answered within \
                     {ANSWER_TIMEOUT:?}: the path stopped"
                ));
            }
        }
    }
    Ok(())
}

/// The ping: handshake, warm-up, `busy_n` round trips back to back, `period_n` at 1 ms;
/// prints the two series on stdout.
fn ping<E: End>(
    e: &mut E,
    round: u64,
    busy_n: u64,
    period_n: u64,
    what: &str,
) -> Result<(), String> {
    rt::no_timer_slack();
    let base = round << ROUND_SHIFT;
    let took = handshake(e, base, what)?;
    eprintln!("  first round trip after {} ms", took.as_millis());
    let mut seq = base + 1;
    let mut in_a_row = 0u32;
    let mut warm = Series::default();
    for _ in 0..WARMUP {
        let t0 = Instant::now();
        e.send(seq)?;
        record(&mut warm, await_answer(e, seq, t0)?, &mut in_a_row)?;
        seq += 1;
    }
    let mut busy = Series {
        rtt: Vec::with_capacity(usize::try_from(busy_n).unwrap_or(0)),
        ..Series::default()
    };
    for _ in 0..busy_n {
        let t0 = Instant::now();
        e.send(seq)?;
        record(&mut busy, await_answer(e, seq, t0)?, &mut in_a_row)?;
        seq += 1;
    }
    let mut period = Series {
        rtt: Vec::with_capacity(usize::try_from(period_n).unwrap_or(0)),
        ..Series::default()
    };
    let mut slot = (rt::now_ns() / PERIOD_NS + 2) * PERIOD_NS;
    for _ in 0..period_n {
        rt::sleep_until(slot);
        let woke = rt::now_ns();
        if woke < slot {
            // A signal: sleep again.
            rt::sleep_until(slot);
        }
        if woke > slot + PERIOD_NS {
            period.late += 1;
        }
        let t0 = Instant::now();
        e.send(seq)?;
        record(&mut period, await_answer(e, seq, t0)?, &mut in_a_row)?;
        seq += 1;
        slot += PERIOD_NS;
        let now = rt::now_ns();
        if slot <= now {
            // Behind (a stall or a lost answer): the next slot ahead, not a burst.
            slot = (now / PERIOD_NS + 1) * PERIOD_NS;
        }
    }
    // The pong exits on STOP; twice, in case one is dropped.
    e.send(base | STOP_LOW)?;
    e.send(base | STOP_LOW)?;
    let mut out = std::io::stdout().lock();
    writeln!(out, "{}", busy.to_line("busy")).map_err(|e| format!("stdout: {e}"))?;
    writeln!(out, "{}", period.to_line("period")).map_err(|e| format!("stdout: {e}"))?;
    out.flush().map_err(|e| format!("stdout: {e}"))
}

/// The pong: answers every message of round `round` until its STOP.
fn pong<E: End>(e: &mut E, round: u64) -> Result<(), String> {
    let mut last = Instant::now();
    let mut spins = 0u32;
    loop {
        match e.poll()? {
            Some(s) if s >> ROUND_SHIFT != round => {}
            Some(s) if s & LOW_MASK == STOP_LOW => return Ok(()),
            Some(s) => {
                e.send(s)?;
                last = Instant::now();
                spins = 0;
            }
            None => {
                spins = spins.wrapping_add(1);
                if spins % 1024 == 0 {
                    let idle = last.elapsed();
                    if idle > PONG_IDLE {
                        return Err(format!("no message for {PONG_IDLE:?}; exiting"));
                    }
                    if idle > PONG_SPIN {
                        std::thread::sleep(Duration::from_micros(200));
                    }
                }
                idle();
            }
        }
    }
}

/// A child role (`--role ping|pong`).
fn run_role(m: &clap::ArgMatches) -> Result<(), String> {
    let get = |k: &str| m.get_one::<String>(k).cloned().unwrap_or_default();
    // `--iterations` and `--period-iterations` are parsed by clap, the hidden ones are text.
    let num = |k: &str| {
        m.get_one::<u64>(k)
            .copied()
            .ok_or_else(|| format!("--{k} is missing"))
    };
    let round = get("round")
        .parse::<u64>()
        .map_err(|e| format!("--round: {e}"))?;
    let is_ping = match get("role").as_str() {
        "ping" => true,
        "pong" => false,
        other => return Err(format!("unknown role `{other}`")),
    };
    match get("path").as_str() {
        "raw" => {
            let mut e = RawEnd::open(&get("addr"), &get("tag"), is_ping)?;
            if is_ping {
                ping(
                    &mut e,
                    round,
                    num("iterations")?,
                    num("period-iterations")?,
                    "the raw Zenoh pong",
                )
            } else {
                pong(&mut e, round)
            }
        }
        "tandem" => {
            let mut e = TandemEnd::open(Path::new(&get("cell")), is_ping)?;
            if is_ping {
                ping(
                    &mut e,
                    round,
                    num("iterations")?,
                    num("period-iterations")?,
                    "the gateways (or the pong node)",
                )
            } else {
                pong(&mut e, round)
            }
        }
        other => Err(format!("unknown path `{other}`")),
    }
}

/// Runs `ip` with `args`; its output in the error when it fails.
fn ip(args: &[&str]) -> Result<(), String> {
    let o = std::process::Command::new("ip")
        .args(args)
        .output()
        .map_err(|e| format!("cannot run `ip` (Debian package iproute2): {e}"))?;
    if o.status.success() {
        Ok(())
    } else {
        Err(format!(
            "`ip {}` failed: {}{}(the bench creates network namespaces and needs root)",
            args.join(" "),
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        ))
    }
}

/// A process the bench started, with what it printed (when captured).
#[derive(Debug)]
struct Proc {
    what: String,
    child: Child,
    /// stderr, as it comes (gateways).
    log: Option<Arc<Mutex<String>>>,
    /// stdout, at exit (pings).
    out: Option<JoinHandle<String>>,
}

/// Everything the bench creates outside itself: namespaces, processes, a directory. Dropping
/// it stops the processes and removes the rest, on every exit path.
#[derive(Debug)]
struct Env {
    ns: Vec<String>,
    addr: [String; 2],
    dir: PathBuf,
    procs: Vec<Proc>,
}

impl Env {
    fn new() -> Result<Env, String> {
        let pid = std::process::id();
        let net = 77 + pid % 100;
        let mut env = Env {
            ns: Vec::new(),
            addr: [format!("10.{net}.0.1"), format!("10.{net}.0.2")],
            dir: std::env::temp_dir().join(format!("tandem-bench-zenoh-{pid}")),
            procs: Vec::new(),
        };
        let names = [format!("tbz{pid}a"), format!("tbz{pid}b")];
        for n in &names {
            ip(&["netns", "add", n])?;
            env.ns.push(n.clone());
        }
        ip(&[
            "link", "add", "va", "netns", &names[0], "type", "veth", "peer", "name", "vb", "netns",
            &names[1],
        ])?;
        for (i, (n, v)) in names.iter().zip(["va", "vb"]).enumerate() {
            let a = format!("{}/24", env.addr[i]);
            ip(&["-n", n, "addr", "add", &a, "dev", v])?;
            ip(&["-n", n, "link", "set", v, "up"])?;
            ip(&["-n", n, "link", "set", "lo", "up"])?;
        }
        std::fs::create_dir_all(&env.dir).map_err(|e| format!("{}: {e}", env.dir.display()))?;
        Ok(env)
    }

    /// Starts `program args` in host `h`'s namespace. Gateways: stderr captured; pings:
    /// stdout captured; all others inherit stderr.
    fn spawn(
        &mut self,
        what: &str,
        h: usize,
        program: &Path,
        args: &[String],
        capture_out: bool,
        capture_err: bool,
    ) -> Result<usize, String> {
        let mut c = std::process::Command::new("ip");
        c.args(["netns", "exec", &self.ns[h]])
            .arg(program)
            .args(args)
            .stdin(Stdio::null())
            .stdout(if capture_out {
                Stdio::piped()
            } else {
                Stdio::null()
            })
            .stderr(if capture_err {
                Stdio::piped()
            } else {
                Stdio::inherit()
            });
        let mut child = c.spawn().map_err(|e| format!("cannot start {what}: {e}"))?;
        let log = child.stderr.take().map(|err| {
            let log = Arc::new(Mutex::new(String::new()));
            let l = Arc::clone(&log);
            std::thread::spawn(move || {
                for line in BufReader::new(err).lines().map_while(Result::ok) {
                    if let Ok(mut g) = l.lock() {
                        g.push_str(&line);
                        g.push('\n');
                    }
                }
            });
            log
        });
        let out = child.stdout.take().map(|mut o| {
            std::thread::spawn(move || {
                let mut s = String::new();
                // Whatever output arrived is shown; a read error leaves it empty.
                let _ = o.read_to_string(&mut s);
                s
            })
        });
        self.procs.push(Proc {
            what: what.to_string(),
            child,
            log,
            out,
        });
        Ok(self.procs.len() - 1)
    }

    /// Whether process `i` still runs.
    fn running(&mut self, i: usize) -> bool {
        self.procs
            .get_mut(i)
            .is_some_and(|p| matches!(p.child.try_wait(), Ok(None)))
    }

    /// The stderr process `i` printed so far.
    fn log(&self, i: usize) -> String {
        self.procs
            .get(i)
            .and_then(|p| p.log.as_ref())
            .and_then(|l| l.lock().ok().map(|g| g.clone()))
            .unwrap_or_default()
    }

    /// Waits up to `grace` for process `i` to exit, then sends SIGTERM, then SIGKILL.
    fn stop(&mut self, i: usize, grace: Duration) {
        let Some(p) = self.procs.get_mut(i) else {
            return;
        };
        let deadline = Instant::now() + grace;
        let mut termed = false;
        loop {
            match p.child.try_wait() {
                Ok(Some(_)) | Err(_) => return,
                Ok(None) if Instant::now() < deadline => {
                    std::thread::sleep(Duration::from_millis(10));
                }
                Ok(None) if !termed => {
                    // A child that already exited cannot be signalled; the wait below handles both.
                    let _ = rt::send_signal(p.child.id(), SIGTERM);
                    termed = true;
                    std::thread::sleep(Duration::from_millis(10));
                }
                Ok(None) if Instant::now() < deadline + Duration::from_secs(3) => {
                    std::thread::sleep(Duration::from_millis(10));
                }
                Ok(None) => {
                    // Last resort after the grace time: a child that is gone already is fine.
                    let _ = p.child.kill();
                    // Reaps the killed child; an error means it is gone already.
                    let _ = p.child.wait();
                    return;
                }
            }
        }
    }
}

impl Drop for Env {
    fn drop(&mut self) {
        for i in 0..self.procs.len() {
            self.stop(i, Duration::ZERO);
        }
        for n in &self.ns {
            // Cleanup in Drop: a namespace already gone is fine, nothing to report to.
            let _ = std::process::Command::new("ip")
                .args(["netns", "del", n])
                .output();
        }
        // Cleanup in Drop: a directory already gone is fine.
        let _ = std::fs::remove_dir_all(&self.dir);
        for h in ["hA", "hB"] {
            ipc::cleanup_dead_nodes(h);
        }
    }
}

/// A virtual axis' dynamics (the cell requires them; the bench never moves an axis).
const DYNAMICS: &str = "max_velocity = 2000.0\nmax_acceleration = 4000.0\n\
max_deceleration = 4000.0\nmax_jerk = 40000.0\nvelocity = 800.0\nacceleration = 3000.0\n\
deceleration = 3000.0\njerk = 30000.0\nemergency_deceleration = 8000.0\n";

/// The two-host cell: leader `ping` on `na` (hA) followed on hB, leader `pong` on `nb` (hB)
/// followed on hA.
fn cell_toml(name: &str, addr: &[String; 2]) -> String {
    // Plain TCP between the gateways, written out (docs/security.md).
    let mut s = format!("[cell]\nname = \"{name}\"\n\n[security]\nmode = \"plain\"\n\n");
    for (h, a) in ["hA", "hB"].iter().zip(addr) {
        s.push_str(&format!(
            "[[hosts]]\nname = \"{h}\"\nlisten = [\"tcp/{a}:{GATEWAY_PORT}\"]\n\n"
        ));
    }
    for (n, h) in [("na", "hA"), ("nb", "hB")] {
        s.push_str(&format!(
            "[[nodes]]\nname = \"{n}\"\ncycle_us = 1000\nhost = \"{h}\"\n\n"
        ));
    }
    for (leader, node, follower, follower_node) in [
        ("ping", "na", "ping_follower", "nb"),
        ("pong", "nb", "pong_follower", "na"),
    ] {
        s.push_str(&format!(
            "[axes.{leader}]\nnode = \"{node}\"\nvirtual = true\n\n\
             [axes.{leader}.leading_value]\ndelay_us = 5000\n\n\
             [axes.{leader}.dynamics]\n{DYNAMICS}\n\
             [axes.{follower}]\nnode = \"{follower_node}\"\nkind = \"synchronous\"\n\
             virtual = true\n\n\
             [axes.{follower}.leaders]\n\"{node}/{leader}\" = \"setpoint\"\n\n\
             [axes.{follower}.dynamics]\n{DYNAMICS}\n"
        ));
    }
    s
}

#[derive(Copy, Clone, Debug, PartialEq, Eq)]
enum PathKind {
    Raw,
    Tandem,
}

impl PathKind {
    fn name(self) -> &'static str {
        match self {
            PathKind::Raw => "raw",
            PathKind::Tandem => "tandem",
        }
    }
}

/// One measurement of a path in a round: starts the pong in B and the ping in A, waits for
/// the ping's series.
#[allow(clippy::too_many_arguments)]
fn measure(
    env: &mut Env,
    gateways: &[usize],
    exe: &Path,
    cell: &Path,
    path: PathKind,
    round: u64,
    busy_n: u64,
    period_n: u64,
) -> Result<(Series, Series), String> {
    let tag = format!("{}-{round}", std::process::id());
    let common = |role: &str| -> Vec<String> {
        [
            "--role",
            role,
            "--path",
            path.name(),
            "--round",
            &round.to_string(),
            "--tag",
            &tag,
            "--addr",
            &env.addr[1],
            "--iterations",
            &busy_n.to_string(),
            "--period-iterations",
            &period_n.to_string(),
            "--spin",
            if PURE_SPIN.load(Ordering::Relaxed) {
                "pure"
            } else {
                "yield"
            },
            "--cell",
        ]
        .iter()
        .map(|s| s.to_string())
        .chain(std::iter::once(cell.display().to_string()))
        .collect()
    };
    let (pong_args, ping_args) = (common("pong"), common("ping"));
    let pong = env.spawn(
        &format!("the {} pong", path.name()),
        1,
        exe,
        &pong_args,
        false,
        false,
    )?;
    let ping = env.spawn(
        &format!("the {} ping", path.name()),
        0,
        exe,
        &ping_args,
        true,
        false,
    )?;
    let limit = CONNECT_TIMEOUT
        + Duration::from_secs(10)
        + Duration::from_micros(2000 * (busy_n + WARMUP) + 3000 * period_n);
    let started = Instant::now();
    let status = loop {
        if rt::termination_requested() {
            return Err("interrupted".into());
        }
        if let Some(p) = env.procs.get_mut(ping) {
            match p.child.try_wait() {
                Ok(Some(s)) => break s,
                Ok(None) => {}
                Err(e) => return Err(format!("waiting for the ping: {e}")),
            }
        }
        if started.elapsed() > limit {
            return Err(format!("the ping did not finish within {limit:?}"));
        }
        for g in gateways {
            if !env.running(*g) {
                return Err(format!(
                    "{} exited early:\n{}",
                    env.procs.get(*g).map_or("a gateway", |p| p.what.as_str()),
                    env.log(*g)
                ));
            }
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let out = env
        .procs
        .get_mut(ping)
        .and_then(|p| p.out.take())
        .and_then(|h| h.join().ok())
        .unwrap_or_default();
    env.stop(pong, Duration::from_secs(2));
    if !status.success() {
        return Err(format!("the ping failed ({status})"));
    }
    let mut busy = None;
    let mut period = None;
    for line in out.lines() {
        match Series::from_line(line) {
            Some((m, s)) if m == "busy" => busy = Some(s),
            Some((m, s)) if m == "period" => period = Some(s),
            _ => {}
        }
    }
    match (busy, period) {
        (Some(b), Some(p)) => Ok((b, p)),
        _ => Err("the ping printed no results".into()),
    }
}

/// The CPU time of the bench's own processes: this one, its reaped children (pings and
/// pongs), and the gateways.
fn own_ticks(env: &Env, gateways: &[usize]) -> u64 {
    process_ticks("self", true)
        + gateways
            .iter()
            .filter_map(|g| env.procs.get(*g))
            .map(|p| process_ticks(&p.child.id().to_string(), false))
            .sum::<u64>()
}

/// The share (%) of the machine's CPU time that other processes used between two readings
/// of ([`machine_ticks`], [`own_ticks`]).
fn others_percent(a: ((u64, u64), u64), b: ((u64, u64), u64)) -> f64 {
    let all = b.0 .0.saturating_sub(a.0 .0);
    let used = b.0 .1.saturating_sub(a.0 .1);
    let own = b.1.saturating_sub(a.1);
    if all == 0 {
        0.0
    } else {
        100.0 * used.saturating_sub(own) as f64 / all as f64
    }
}

/// One-way (RTT / 2) in µs.
fn one_way_us(rtt_ns: u64) -> f64 {
    rtt_ns as f64 / 2000.0
}

/// A row of the table: the merged rounds and the p50 of each.
#[derive(Debug, Default)]
struct Row {
    all: Series,
    p50s: Vec<f64>,
}

impl Row {
    fn add(&mut self, mut s: Series) {
        s.rtt.sort_unstable();
        self.p50s.push(one_way_us(quantile(&s.rtt, 0.5)));
        self.all.rtt.extend_from_slice(&s.rtt);
        self.all.lost += s.lost;
        self.all.late += s.late;
    }
}

fn main() -> ExitCode {
    let hidden = |name: &'static str| Arg::new(name).long(name).hide(true);
    let m = Command::new("tandem-bench-zenoh")
        .about(
            "One-way leading-value latency between two hosts (network namespaces): raw Zenoh \
             and tandem's node → gateway → Zenoh → gateway → node path, back to back and at a \
             1 ms period, in the same run (needs root)",
        )
        .arg(
            Arg::new("iterations")
                .long("iterations")
                .value_parser(clap::value_parser!(u64).range(1..))
                .default_value("20000")
                .help("Round trips per busy measurement (per path and round)"),
        )
        .arg(
            Arg::new("period-iterations")
                .long("period-iterations")
                .value_parser(clap::value_parser!(u64).range(1..))
                .default_value("5000")
                .help("Round trips per 1 ms-period measurement (per path and round)"),
        )
        .arg(
            Arg::new("rounds")
                .long("rounds")
                .value_parser(clap::value_parser!(u64).range(1..100))
                .default_value("3")
                .help("Rounds of raw and tandem (their order alternates); the table merges them"),
        )
        .arg(
            Arg::new("quick")
                .long("quick")
                .action(ArgAction::SetTrue)
                .help("10x fewer round trips and one round (a smoke test)"),
        )
        .arg(
            Arg::new("spin")
                .long("spin")
                .value_parser(["yield", "pure"])
                .default_value("yield")
                .help(
                    "How receivers busy-poll: `yield` (sched_yield between empty polls) or \
                     `pure` (never give up the CPU; with 2 CPUs the I/O threads then wait \
                     for preemption)",
                ),
        )
        .arg(hidden("role"))
        .arg(hidden("path"))
        .arg(hidden("round"))
        .arg(hidden("tag"))
        .arg(hidden("addr"))
        .arg(hidden("cell"))
        .arg(cargo_bench_flag())
        .get_matches();

    PURE_SPIN.store(
        m.get_one::<String>("spin").map(String::as_str) == Some("pure"),
        Ordering::Relaxed,
    );
    if let Some(role) = m.get_one::<String>("role") {
        return match run_role(&m) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                let path = m.get_one::<String>("path").map_or("", String::as_str);
                eprintln!("tandem-bench-zenoh {path} {role}: error: {e}");
                ExitCode::FAILURE
            }
        };
    }
    let (busy_n, period_n, rounds) = tandem_bench::ping_pong_sizes(&m, 20_000);
    rt::install_termination_handler();
    match run(busy_n.max(1), period_n.max(1), rounds) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("tandem-bench-zenoh: error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(busy_n: u64, period_n: u64, rounds: u64) -> Result<(), String> {
    let exe = std::env::current_exe().map_err(|e| format!("own executable: {e}"))?;
    let gateway = sibling_binary("tandem-gateway").ok_or_else(|| {
        format!(
            "tandem-gateway is missing beside {}: build it first (cargo build --release -p \
             tandem-gateway)",
            exe.display()
        )
    })?;
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    let steal0 = Steal::start();
    let started = Instant::now();
    for h in ["hA", "hB"] {
        ipc::cleanup_dead_nodes(h);
    }
    let mut env = Env::new()?;
    let cell = env.dir.join("cell.toml");
    let cell_name = format!("bz{}", std::process::id());
    std::fs::write(&cell, cell_toml(&cell_name, &env.addr))
        .map_err(|e| format!("{}: {e}", cell.display()))?;
    tandem_config::load(&cell).map_err(|e| format!("the generated cell: {e}"))?;
    let mut gateways = Vec::new();
    for (i, h) in ["hA", "hB"].iter().enumerate() {
        let args = [cell.display().to_string(), "--host".into(), h.to_string()];
        gateways.push(env.spawn(
            &format!("the gateway of {h}"),
            i,
            &gateway,
            &args,
            false,
            true,
        )?);
    }
    eprintln!(
        "tandem-bench-zenoh: namespaces {} ({}) and {} ({}), veth; gateways started; {rounds} \
         round(s) of {busy_n} busy + {period_n} period round trips per path",
        env.ns[0], env.addr[0], env.ns[1], env.addr[1]
    );
    let keys = [
        (PathKind::Raw, "busy"),
        (PathKind::Tandem, "busy"),
        (PathKind::Raw, "period"),
        (PathKind::Tandem, "period"),
    ];
    let mut rows: Vec<Row> = keys.iter().map(|_| Row::default()).collect();
    let mut others = Vec::new();
    let row_of = |p: PathKind, mode: &str| keys.iter().position(|k| *k == (p, mode)).unwrap_or(0);
    for r in 0..rounds {
        let order = if r % 2 == 0 {
            [PathKind::Raw, PathKind::Tandem]
        } else {
            [PathKind::Tandem, PathKind::Raw]
        };
        for path in order {
            eprintln!("round {}/{rounds}: {}", r + 1, path.name());
            let st = Steal::start();
            let o0 = (machine_ticks(), own_ticks(&env, &gateways));
            let (busy, period) = measure(
                &mut env,
                &gateways,
                &exe,
                &cell,
                path,
                r + 1,
                busy_n,
                period_n,
            )
            .map_err(|e| {
                let logs: Vec<String> = gateways.iter().map(|g| env.log(*g)).collect();
                format!(
                    "round {} {}: {e}\ngateway output:\n{}",
                    r + 1,
                    path.name(),
                    logs.join("")
                )
            })?;
            let st = st.percent();
            let other = others_percent(o0, (machine_ticks(), own_ticks(&env, &gateways)));
            others.push(other);
            let p50 = |s: &Series| {
                let mut v = s.rtt.clone();
                v.sort_unstable();
                fmt_us(one_way_us(quantile(&v, 0.5)))
            };
            eprintln!(
                "  p50 busy {} µs, period {} µs; lost {}; steal {st:.1} %; other processes \
                 {other:.0} % of the CPUs",
                p50(&busy),
                p50(&period),
                busy.lost + period.lost
            );
            rows[row_of(path, "busy")].add(busy);
            rows[row_of(path, "period")].add(period);
        }
    }
    // Stop the gateways: their last line has their counters.
    for g in &gateways {
        // A gateway that already exited cannot be signalled; stop() below waits for both.
        let _ = env
            .procs
            .get(*g)
            .map(|p| rt::send_signal(p.child.id(), SIGTERM));
    }
    for g in &gateways {
        env.stop(*g, Duration::from_secs(3));
    }
    let gateway_logs: Vec<String> = gateways.iter().map(|g| env.log(*g)).collect();
    drop(env);
    let elapsed = started.elapsed();
    let steal = steal0.percent();
    for row in &mut rows {
        row.all.rtt.sort_unstable();
    }
    report(&rows, &keys, rounds, &gateway_logs);
    println!(
        "Load average at the start: {}. Other processes used {} % of the CPUs during the \
         measurements (per measurement; 50 % = one CPU). Hypervisor steal over the run: \
         {steal:.1} %. Took {:.1} s.",
        load.split_whitespace()
            .take(3)
            .collect::<Vec<_>>()
            .join(" "),
        others
            .iter()
            .map(|x| format!("{x:.0}"))
            .collect::<Vec<_>>()
            .join(" / "),
        elapsed.as_secs_f64()
    );
    Ok(())
}

fn report(rows: &[Row], keys: &[(PathKind, &str)], rounds: u64, gateway_logs: &[String]) {
    let row_of = |p: PathKind, mode: &str| keys.iter().position(|k| *k == (p, mode));
    println!();
    println!(
        "tandem-bench-zenoh: one-way latency = RTT/2 in µs between two network namespaces (veth); \
         payload: a leading value, {} bytes on Zenoh; receivers busy-poll ({}); {rounds} round(s) \
         merged",
        json::encode_leading_value(&sample(0, 0)).len(),
        if PURE_SPIN.load(Ordering::Relaxed) {
            "pure spin"
        } else {
            "sched_yield between empty polls"
        }
    );
    println!(
        "{:<7} {:<7} {:>7} {:>5} {:>7} {:>7} {:>7} {:>7} {:>7} {:>11}",
        "path", "mode", "n", "lost", "p50", "p99", "p99.9", "max", "mean", "tandem/raw"
    );
    let mut ratios = Vec::new();
    for (i, (path, mode)) in keys.iter().enumerate() {
        let v = &rows[i].all.rtt;
        let mean = if v.is_empty() {
            0.0
        } else {
            v.iter().map(|x| *x as f64).sum::<f64>() / v.len() as f64 / 2000.0
        };
        let p50 = one_way_us(quantile(v, 0.5));
        let ratio = if *path == PathKind::Tandem {
            let raw = row_of(PathKind::Raw, mode)
                .map_or(0.0, |j| one_way_us(quantile(&rows[j].all.rtt, 0.5)));
            if raw > 0.0 {
                ratios.push((*mode, p50 / raw));
                format!("{:.2}", p50 / raw)
            } else {
                "-".into()
            }
        } else {
            String::new()
        };
        println!(
            "{:<7} {:<7} {:>7} {:>5} {:>7} {:>7} {:>7} {:>7} {:>7} {:>11}",
            path.name(),
            mode,
            v.len(),
            rows[i].all.lost,
            fmt_us(p50),
            fmt_us(one_way_us(quantile(v, 0.99))),
            fmt_us(one_way_us(quantile(v, 0.999))),
            fmt_us(one_way_us(quantile(v, 1.0))),
            fmt_us(mean),
            ratio
        );
    }
    if rounds > 1 {
        for mode in ["busy", "period"] {
            let col = |p: PathKind| {
                row_of(p, mode)
                    .map(|i| rows[i].p50s.clone())
                    .unwrap_or_default()
            };
            let (raw, tandem) = (col(PathKind::Raw), col(PathKind::Tandem));
            let rs: Vec<f64> = raw
                .iter()
                .zip(&tandem)
                .map(|(r, t)| if *r > 0.0 { t / r } else { 0.0 })
                .collect();
            let list = |v: &[f64]| v.iter().map(|x| fmt_us(*x)).collect::<Vec<_>>().join(" ");
            println!(
                "{mode:<6} p50 per round: raw {} | tandem {} | ratio {} (median ratio {:.2})",
                list(&raw),
                list(&tandem),
                rs.iter()
                    .map(|x| format!("{x:.2}"))
                    .collect::<Vec<_>>()
                    .join(" "),
                median(rs.clone())
            );
        }
    }
    let verdict = ratios
        .iter()
        .map(|(mode, r)| {
            format!(
                "{mode} {} ({r:.2}×)",
                if *r <= 1.5 { "PASS" } else { "ABOVE" }
            )
        })
        .collect::<Vec<_>>()
        .join(", ");
    println!("target: tandem ≤ 1.5× raw Zenoh at p50: {verdict}");
    let late: u64 = keys
        .iter()
        .enumerate()
        .filter(|(_, (_, m))| *m == "period")
        .map(|(i, _)| rows[i].all.late)
        .sum();
    println!(
        "lost = not answered within {} ms; mean over the answered ones. Period wake-ups more \
         than 1 ms late: {late}.",
        ANSWER_TIMEOUT.as_millis()
    );

    // The follower's view: a sample is needed D - 1 ms after it was sent (the follower
    // cycle), later ones must be extrapolated. Lost ones count as late.
    println!();
    println!(
        "sync error a follower would see (1 ms follower cycle): share of the period-mode one-way \
         latencies above D − 1 ms, i.e. leading values that must be extrapolated (lost ones count)"
    );
    println!(
        "{:>6} {:>12} {:>16} {:>9} {:>9}",
        "D (ms)", "budget (µs)", "tandem late", "tandem", "raw"
    );
    let share = |row: Option<usize>, budget_ns: i64| -> (u64, u64) {
        let Some(r) = row.and_then(|i| rows.get(i)) else {
            return (0, 0);
        };
        let over = r
            .all
            .rtt
            .iter()
            .filter(|x| (**x as f64 / 2.0) > budget_ns as f64)
            .count() as u64;
        (over + r.all.lost, r.all.rtt.len() as u64 + r.all.lost)
    };
    for d in DELAYS_MS {
        let budget = (d - 1) * 1_000_000;
        let (t_over, t_n) = share(row_of(PathKind::Tandem, "period"), budget);
        let (r_over, r_n) = share(row_of(PathKind::Raw, "period"), budget);
        let pct = |o: u64, n: u64| {
            if n == 0 {
                "-".to_string()
            } else {
                format!("{:.3} %", 100.0 * o as f64 / n as f64)
            }
        };
        println!(
            "{:>6} {:>12} {:>16} {:>9} {:>9}",
            d,
            budget / 1000,
            format!("{t_over}/{t_n}"),
            pct(t_over, t_n),
            pct(r_over, r_n)
        );
    }
    println!();
    for l in gateway_logs {
        for line in l
            .lines()
            .filter(|x| x.contains("stopped;") || x.contains("warning") || x.contains("error"))
        {
            println!("{line}");
        }
    }
}
