//! `tandem-bench-tls`: the latency of a leading value between two hosts' gateways over mTLS
//! against plain TCP, side by side in one run (issue 12: at most 1.2x).
//!
//! Two generated two-host cells, one `[security] mode = "plain"` (TCP) and one `"mtls"` with
//! certificates made by `tandem certs` (`tandem_cli::certs::certs`, into a temporary directory
//! removed at the end). For each cell, two Zenoh sessions are opened in this process with
//! exactly the configuration of the hosts' gateways (`tandem_gateway::zenoh_config`: peer mode,
//! loopback TCP endpoints, and for mTLS the TLS keys, the client certificate required, and the
//! cell's access control with default deny). Host 1's session puts a leading value of leader
//! `ping` (the 64-byte wire form of a [`LeadingValueSample`], with the gateways' QoS:
//! `Priority::RealTime`, express, `CongestionControl::Drop`); host 2's session answers each on
//! leader `pong`'s key from its subscriber's callback; host 1 busy-polls for the answer
//! (`sched_yield` between empty polls). One-way latency is RTT / 2.
//!
//! The pings go at a fixed period (default 1 ms, the cycle of a leader, on an absolute grid).
//! Each round measures both links one after the other, the order alternating from round to
//! round; the table merges the rounds and gives each round's medians, and the ratio of the
//! medians mTLS / plain. An answer not back within 100 ms is lost.
//!
//! ```text
//! cargo bench -p tandem-bench --bench tls -- [--samples 5000] [--rounds 6] [--period-us 1000]
//! ```

use clap::{Arg, ArgAction, Command};
use std::path::Path;
use std::process::ExitCode;
use std::time::{Duration, Instant};
use tandem_bench::{cargo_bench_flag, fmt_us, median, quantile, ratio};
use tandem_protocol::json;
use tandem_protocol::keys;
use tandem_protocol::wire::{LeadingValueSample, LV_VALID};
use tandem_rt as rt;
use zenoh::handlers::FifoChannelHandler;
use zenoh::qos::{CongestionControl, Priority};
use zenoh::sample::{Locality, Sample};
use zenoh::Wait;

/// The first round trip must succeed within this (the sessions connect).
const CONNECT_TIMEOUT: Duration = Duration::from_secs(20);
/// An answer not back within this is lost.
const ANSWER_TIMEOUT: Duration = Duration::from_millis(100);
/// Round trips after the first answer that are not recorded.
const WARMUP: u64 = 500;

/// The two links measured.
const LINKS: [&str; 2] = ["plain", "mtls"];

/// The cell of one link: two hosts on loopback, leader `ping` on host 1 and `pong` on host 2.
fn cell_toml(name: &str, mtls: bool, ports: [u16; 2]) -> String {
    let (proto, security) = if mtls {
        ("tls", "mode = \"mtls\"\noperators = [\"op\"]")
    } else {
        ("tcp", "mode = \"plain\"")
    };
    let axis = |axis: &str, node: &str| {
        format!(
            "[axes.{axis}]\nnode = \"{node}\"\nvirtual = true\n\n[axes.{axis}.dynamics]\n\
             max_velocity = 100.0\nmax_acceleration = 1000.0\nmax_deceleration = 1000.0\n\
             max_jerk = 10000.0\nvelocity = 50.0\nacceleration = 500.0\ndeceleration = 500.0\n\
             jerk = 5000.0\nemergency_deceleration = 2000.0\n\n"
        )
    };
    format!(
        "[cell]\nname = \"{name}\"\n\n[security]\n{security}\n\n\
         [[hosts]]\nname = \"h1\"\nlisten = [\"{proto}/127.0.0.1:{}\"]\n\n\
         [[hosts]]\nname = \"h2\"\nlisten = [\"{proto}/127.0.0.1:{}\"]\n\n\
         [[nodes]]\nname = \"na\"\ncycle_us = 1000\nhost = \"h1\"\n\n\
         [[nodes]]\nname = \"nb\"\ncycle_us = 1000\nhost = \"h2\"\n\n{}{}",
        ports[0],
        ports[1],
        axis("ping", "na"),
        axis("pong", "nb"),
    )
}

/// A free TCP port on loopback (bound and released; the sessions bind it a moment later).
fn free_port() -> Result<u16, String> {
    let l = std::net::TcpListener::bind("127.0.0.1:0").map_err(|e| format!("a free port: {e}"))?;
    l.local_addr()
        .map(|a| a.port())
        .map_err(|e| format!("a free port: {e}"))
}

/// One link: host 1's session (ping), host 2's (pong, answering from its callback).
struct Link {
    publisher: zenoh::pubsub::Publisher<'static>,
    answers: zenoh::pubsub::Subscriber<FifoChannelHandler<Sample>>,
    _pong: (zenoh::pubsub::Subscriber<()>, zenoh::Session),
    _ping: zenoh::Session,
}

/// A publisher with the gateways' QoS for leading values.
fn lv_publisher(
    s: &zenoh::Session,
    key: String,
) -> Result<zenoh::pubsub::Publisher<'static>, String> {
    s.declare_publisher(key.clone())
        .priority(Priority::RealTime)
        .express(true)
        .congestion_control(CongestionControl::Drop)
        .allowed_destination(Locality::Remote)
        .wait()
        .map_err(|e| format!("publisher {key}: {e}"))
}

impl Link {
    /// Writes the cell of `link` into `dir` (with its certificates for mTLS) and opens both
    /// hosts' sessions with the gateways' configuration.
    fn open(dir: &Path, link: &str) -> Result<Self, String> {
        let mtls = link == "mtls";
        let cell_dir = dir.join(link);
        std::fs::create_dir_all(&cell_dir).map_err(|e| format!("{}: {e}", cell_dir.display()))?;
        let path = cell_dir.join("cell.toml");
        let name = format!("bench{link}{}", std::process::id());
        let src = cell_toml(&name, mtls, [free_port()?, free_port()?]);
        std::fs::write(&path, src).map_err(|e| format!("{}: {e}", path.display()))?;
        if mtls {
            let o = tandem_cli::certs::CertsOptions {
                cell: path.clone(),
                out: None,
                days: 1,
            };
            tandem_cli::certs::certs(&o, &mut std::io::sink())
                .map_err(|e| format!("tandem certs: {e}"))?;
        }
        let cell = tandem_config::load(&path).map_err(|e| format!("{e}"))?;
        let open = |h: usize| -> Result<zenoh::Session, String> {
            let c = tandem_gateway::zenoh_config(&cell, h).map_err(|e| format!("{e}"))?;
            zenoh::open(c)
                .wait()
                .map_err(|e| format!("{link}: opening host {}'s session: {e}", h + 1))
        };
        let pong = open(1)?;
        let ping = open(0)?;
        let (ping_key, pong_key) = (
            keys::leading_value(&name, "ping", false),
            keys::leading_value(&name, "pong", false),
        );
        let back = lv_publisher(&pong, pong_key.clone())?;
        let relay = pong
            .declare_subscriber(ping_key.clone())
            .callback(move |s: Sample| {
                // A failed put is a lost round trip, counted by the pinger.
                let _ = back.put(s.payload().to_bytes().to_vec()).wait();
            })
            .wait()
            .map_err(|e| format!("subscriber {ping_key}: {e}"))?;
        let answers = ping
            .declare_subscriber(pong_key.clone())
            .wait()
            .map_err(|e| format!("subscriber {pong_key}: {e}"))?;
        let publisher = lv_publisher(&ping, ping_key)?;
        Ok(Self {
            publisher,
            answers,
            _pong: (relay, pong),
            _ping: ping,
        })
    }

    /// One round trip of message `seq`: its time (ns), or `None` if not answered in time.
    fn round_trip(&self, seq: u64, timeout: Duration) -> Result<Option<u64>, String> {
        let s = LeadingValueSample {
            t_ns: rt::now_ns(),
            seq,
            p: (seq & 0xFFFF) as f64 * 1e-3,
            v: 1.0,
            a: 0.0,
            modulo_start: 0.0,
            modulo_length: 0.0,
            status: LV_VALID,
            leader: 0,
        };
        let t0 = Instant::now();
        self.publisher
            .put(json::encode_leading_value(&s))
            .wait()
            .map_err(|e| format!("put: {e}"))?;
        while t0.elapsed() < timeout {
            match self.answers.try_recv() {
                Ok(Some(a)) => {
                    let back = json::decode_leading_value(&a.payload().to_bytes())
                        .map_err(|e| format!("answer: {e}"))?;
                    if back.seq == seq {
                        return Ok(Some(t0.elapsed().as_nanos() as u64));
                    }
                }
                Ok(None) => std::thread::yield_now(),
                Err(e) => return Err(format!("receive: {e}")),
            }
        }
        Ok(None)
    }
}

/// The round trips of one measurement (ns) and the lost ones.
#[derive(Default)]
struct Series {
    rtt: Vec<u64>,
    lost: u64,
}

/// `n` round trips at `period_ns` on an absolute grid, after [`WARMUP`] unrecorded ones.
fn measure(link: &Link, base: u64, n: u64, period_ns: i64) -> Result<Series, String> {
    let mut s = Series::default();
    let mut next = rt::now_ns();
    for i in 0..WARMUP + n {
        next += period_ns;
        rt::sleep_until(next);
        if rt::termination_requested() {
            return Err("interrupted".into());
        }
        let rtt = link.round_trip(base + i, ANSWER_TIMEOUT)?;
        if i >= WARMUP {
            match rtt {
                Some(r) => s.rtt.push(r),
                None => s.lost += 1,
            }
        }
    }
    s.rtt.sort_unstable();
    Ok(s)
}

/// Waits for the first answer of `link` (the sessions connect).
fn connect(link: &Link, what: &str) -> Result<(), String> {
    let t0 = Instant::now();
    let mut seq = 1 << 40;
    while t0.elapsed() < CONNECT_TIMEOUT {
        seq += 1;
        if link.round_trip(seq, Duration::from_millis(200))?.is_some() {
            return Ok(());
        }
    }
    Err(format!(
        "{what}: no answer within {CONNECT_TIMEOUT:?} (the sessions did not connect)"
    ))
}

/// One-way µs of a round trip in ns.
fn one_way_us(rtt_ns: u64) -> f64 {
    rtt_ns as f64 / 2000.0
}

fn main() -> ExitCode {
    let m = Command::new("tandem-bench-tls")
        .about(
            "One-way leading-value latency between two hosts' gateway sessions on loopback, \
             mTLS (with the cell's access control) against plain TCP, in one run",
        )
        .arg(
            Arg::new("samples")
                .long("samples")
                .value_parser(clap::value_parser!(u64).range(1..))
                .default_value("5000")
                .help("Round trips per link and round"),
        )
        .arg(
            Arg::new("rounds")
                .long("rounds")
                .value_parser(clap::value_parser!(u64).range(1..100))
                .default_value("6")
                .help("Rounds of both links (their order alternates)"),
        )
        .arg(
            Arg::new("period-us")
                .long("period-us")
                .value_parser(clap::value_parser!(u64).range(1..1_000_000))
                .default_value("1000")
                .help("The ping period (µs): a leader's cycle"),
        )
        .arg(
            Arg::new("quick")
                .long("quick")
                .action(ArgAction::SetTrue)
                .help("500 round trips, two rounds (a smoke test)"),
        )
        .arg(cargo_bench_flag())
        .get_matches();
    let quick = m.get_flag("quick");
    let samples = if quick {
        500
    } else {
        m.get_one::<u64>("samples").copied().unwrap_or(5000)
    };
    let rounds = if quick {
        2
    } else {
        m.get_one::<u64>("rounds").copied().unwrap_or(6)
    };
    let period_us = m.get_one::<u64>("period-us").copied().unwrap_or(1000);
    rt::install_termination_handler();
    let dir = std::env::temp_dir().join(format!("tandem-bench-tls-{}", std::process::id()));
    let result = run(&dir, samples, rounds, period_us as i64 * 1000);
    // The temporary directory holds only this run's cells and certificates.
    let _ = std::fs::remove_dir_all(&dir);
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("tandem-bench-tls: error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(dir: &Path, samples: u64, rounds: u64, period_ns: i64) -> Result<(), String> {
    let links = [Link::open(dir, LINKS[0])?, Link::open(dir, LINKS[1])?];
    for (l, what) in links.iter().zip(LINKS) {
        connect(l, what)?;
    }
    println!(
        "tandem-bench-tls: {rounds} rounds of {samples} round trips per link at a {} µs period, \
         {} B leading values, loopback, one-way = RTT/2",
        period_ns / 1000,
        json::encode_leading_value(&LeadingValueSample {
            t_ns: 0,
            seq: 0,
            p: 0.0,
            v: 0.0,
            a: 0.0,
            modulo_start: 0.0,
            modulo_length: 0.0,
            status: 0,
            leader: 0,
        })
        .len()
    );
    let mut all: [Series; 2] = Default::default();
    let mut round_medians: [Vec<f64>; 2] = Default::default();
    for r in 0..rounds {
        let order: [usize; 2] = if r % 2 == 0 { [0, 1] } else { [1, 0] };
        let mut line = format!("round {}:", r + 1);
        for i in order {
            let base = (r + 1) << 32 | (i as u64) << 31;
            let s = measure(&links[i], base, samples, period_ns)?;
            let p50 = one_way_us(quantile(&s.rtt, 0.5));
            line.push_str(&format!(" {} p50 {} µs,", LINKS[i], fmt_us(p50)));
            round_medians[i].push(p50);
            all[i].rtt.extend_from_slice(&s.rtt);
            all[i].lost += s.lost;
        }
        let n = round_medians[0].len();
        line.push_str(&format!(
            " ratio {:.3}",
            ratio(round_medians[1][n - 1], round_medians[0][n - 1])
        ));
        println!("{line}");
    }
    println!("\n| link | samples | lost | p50 one-way (µs) | p90 | p99 | max |");
    println!("|---|---|---|---|---|---|---|");
    for (i, s) in all.iter_mut().enumerate() {
        s.rtt.sort_unstable();
        let q = |x: f64| fmt_us(one_way_us(quantile(&s.rtt, x)));
        println!(
            "| {} | {} | {} | {} | {} | {} | {} |",
            LINKS[i],
            s.rtt.len(),
            s.lost,
            q(0.5),
            q(0.9),
            q(0.99),
            q(1.0)
        );
    }
    let p50 = |i: usize| one_way_us(quantile(&all[i].rtt, 0.5));
    let p99 = |i: usize| one_way_us(quantile(&all[i].rtt, 0.99));
    let merged = ratio(p50(1), p50(0));
    let per_round: Vec<f64> = round_medians[1]
        .iter()
        .zip(&round_medians[0])
        .map(|(m, p)| ratio(*m, *p))
        .collect();
    println!(
        "\nmTLS / plain: median {merged:.3} (median of the rounds' ratios {:.3}), p99 {:.3}; \
         target at most 1.2: {}",
        median(per_round),
        ratio(p99(1), p99(0)),
        if merged <= 1.2 { "met" } else { "NOT met" }
    );
    Ok(())
}
