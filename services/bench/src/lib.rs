//! The statistics tandem's benchmarks share: latency histograms and quantiles, medians and
//! ratios, CPU time (process, threads, machine) and the hypervisor's steal, resident memory,
//! and how a bench finds its sibling programs and accepts cargo's `--bench` flag.
//!
//! The benches themselves are in `benches/` (`axes`, `latency`, `zenoh`); run one with
//! `cargo bench -p tandem-bench --bench axes -- --help`.
//!
//! ```
//! use tandem_bench::{median, quantile, Hist};
//! let mut h = Hist::new(1_000);
//! for rtt in [800, 900, 1_000, 5_000] {
//!     h.record(rtt);
//! }
//! assert_eq!(h.quantile(0.5), 900);
//! assert_eq!(h.quantile(1.0), 5_000);
//! assert_eq!(quantile(&[1, 2, 3, 4], 0.5), 2);
//! assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
//! ```

use std::path::PathBuf;
use tandem_rt as rt;

pub mod fuzz;

/// Durations in 1 ns bins up to a limit, the rest kept exactly.
#[derive(Debug, Clone)]
pub struct Hist {
    bins: Vec<u32>,
    slow: Vec<u64>,
    n: u64,
    sum_ns: u128,
}

impl Hist {
    /// A histogram with `bins` 1 ns bins, every page touched now (not on the measured path).
    pub fn new(bins: usize) -> Self {
        let mut bins = vec![0u32; bins];
        bins.iter_mut().for_each(|b| *b = std::hint::black_box(0));
        Self {
            bins,
            slow: Vec::with_capacity(1 << 16),
            n: 0,
            sum_ns: 0,
        }
    }

    /// Records one duration (ns).
    #[inline]
    pub fn record(&mut self, ns: u64) {
        match self.bins.get_mut(usize::try_from(ns).unwrap_or(usize::MAX)) {
            Some(b) => *b = b.saturating_add(1),
            None => self.slow.push(ns),
        }
        self.n += 1;
        self.sum_ns += u128::from(ns);
    }

    /// Adds the durations of `o`.
    pub fn merge(&mut self, o: &Hist) {
        for (a, b) in self.bins.iter_mut().zip(&o.bins) {
            *a = a.saturating_add(*b);
        }
        self.slow.extend_from_slice(&o.slow);
        self.n += o.n;
        self.sum_ns += o.sum_ns;
    }

    /// Durations recorded.
    pub fn count(&self) -> u64 {
        self.n
    }

    /// The mean (ns), 0 when empty.
    pub fn mean(&self) -> f64 {
        if self.n == 0 {
            0.0
        } else {
            self.sum_ns as f64 / self.n as f64
        }
    }

    /// The `q` quantile (ns); the max for `q >= 1`, 0 when empty.
    pub fn quantile(&self, q: f64) -> u64 {
        if self.n == 0 {
            return 0;
        }
        let rank = ((q.min(1.0) * self.n as f64).ceil() as u64).clamp(1, self.n);
        let mut seen = 0u64;
        for (i, b) in self.bins.iter().enumerate() {
            seen += u64::from(*b);
            if seen >= rank {
                return i as u64;
            }
        }
        let mut slow = self.slow.clone();
        slow.sort_unstable();
        let i = usize::try_from(rank - seen).unwrap_or(usize::MAX);
        slow.get(i.saturating_sub(1))
            .or(slow.last())
            .copied()
            .unwrap_or(0)
    }
}

/// The `q` quantile of sorted `v` (the max for `q >= 1`, 0 when empty).
pub fn quantile(v: &[u64], q: f64) -> u64 {
    if v.is_empty() {
        return 0;
    }
    let n = v.len();
    let rank = ((q.min(1.0) * n as f64).ceil() as usize).clamp(1, n);
    v[rank - 1]
}

/// The median of `v` (the mean of the middle two for an even count; 0 when empty).
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => 0.0,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

/// The sizes of a ping-pong run from its command line: (busy iterations, period iterations,
/// rounds) from `--iterations` (default `busy_default`), `--period-iterations` (default 5,000)
/// and `--rounds` (default 3); `--quick` divides the iterations by 10 and runs one round.
pub fn ping_pong_sizes(m: &clap::ArgMatches, busy_default: u64) -> (u64, u64, u64) {
    let quick = m.get_flag("quick");
    let scale = if quick { 10 } else { 1 };
    let busy = m
        .get_one::<u64>("iterations")
        .copied()
        .unwrap_or(busy_default)
        / scale;
    let period = m
        .get_one::<u64>("period-iterations")
        .copied()
        .unwrap_or(5000)
        / scale;
    let rounds = if quick {
        1
    } else {
        m.get_one::<u64>("rounds").copied().unwrap_or(3)
    };
    (busy, period, rounds)
}

/// `a / b`, 0 when `b` is 0.
pub fn ratio(a: f64, b: f64) -> f64 {
    if b == 0.0 {
        0.0
    } else {
        a / b
    }
}

/// A duration in µs with 3 significant digits or so: `123`, `12.3`, `1.23`.
pub fn fmt_us(x: f64) -> String {
    if x >= 100.0 {
        format!("{x:.0}")
    } else if x >= 10.0 {
        format!("{x:.1}")
    } else {
        format!("{x:.2}")
    }
}

/// Bytes in MiB.
pub fn mib(bytes: u64) -> f64 {
    bytes as f64 / (1024.0 * 1024.0)
}

/// This process' resident memory (bytes), 0 if unknown.
pub fn rss() -> u64 {
    rt::resident_bytes().unwrap_or(0)
}

/// The first eight fields of the `cpu` line of /proc/stat (clock ticks, all CPUs): user, nice,
/// system, idle, iowait, irq, softirq, steal; zeros where unreadable.
fn proc_stat_cpu() -> [u64; 8] {
    let stat = std::fs::read_to_string("/proc/stat").unwrap_or_default();
    let mut f = [0u64; 8];
    let fields = stat.lines().next().unwrap_or("").split_whitespace().skip(1);
    for (slot, x) in f.iter_mut().zip(fields) {
        *slot = x.parse().unwrap_or(0);
    }
    f
}

/// The hypervisor's steal between two points of a run, from `/proc/stat`: (all ticks, steal).
#[derive(Debug, Clone, Copy)]
pub struct Steal((u64, u64));

impl Steal {
    fn now() -> (u64, u64) {
        let f = proc_stat_cpu();
        (f.iter().sum(), f[7])
    }

    /// Starts measuring.
    pub fn start() -> Self {
        Self(Self::now())
    }

    /// The steal since [`Steal::start`], in % of the machine's CPU time.
    pub fn percent(&self) -> f64 {
        let (a, b) = (self.0, Self::now());
        let total = b.0.saturating_sub(a.0);
        if total == 0 {
            0.0
        } else {
            100.0 * b.1.saturating_sub(a.1) as f64 / total as f64
        }
    }
}

/// The machine's CPU time in clock ticks, all CPUs: (all, used), from /proc/stat; used is
/// neither idle, iowait nor steal.
pub fn machine_ticks() -> (u64, u64) {
    let f = proc_stat_cpu();
    let all: u64 = f.iter().sum();
    let unused = f[3] + f[4] + f[7];
    (all, all.saturating_sub(unused))
}

/// The fields after the command name of a `/proc/.../stat` line.
fn stat_fields(stat: &str) -> Vec<u64> {
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    rest.split_whitespace()
        .skip(11)
        .take(4)
        .map(|x| x.parse().unwrap_or(0))
        .collect()
}

/// The CPU time (clock ticks) of a process from `/proc/<pid>/stat` (`self` for this one):
/// user + system, with its reaped children's when `children`.
pub fn process_ticks(pid: &str, children: bool) -> u64 {
    let s = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap_or_default();
    stat_fields(&s)
        .iter()
        .take(if children { 4 } else { 2 })
        .sum()
}

/// The threads of this process: (tid, name, user + system CPU in clock ticks).
pub fn thread_ticks() -> Vec<(u32, String, u64)> {
    let Ok(dir) = std::fs::read_dir("/proc/self/task") else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for entry in dir.flatten() {
        let Some(tid) = entry
            .file_name()
            .to_str()
            .and_then(|x| x.parse::<u32>().ok())
        else {
            continue;
        };
        let Ok(stat) = std::fs::read_to_string(entry.path().join("stat")) else {
            continue;
        };
        let (Some(open), Some(close)) = (stat.find('('), stat.rfind(')')) else {
            continue;
        };
        let name = stat.get(open + 1..close).unwrap_or("?").to_string();
        out.push((tid, name, stat_fields(&stat).iter().take(2).sum()));
    }
    out
}

/// A program built beside this one: in the same directory, or one up (a bench runs from
/// `target/release/deps`, the programs are in `target/release`).
pub fn sibling_binary(name: &str) -> Option<PathBuf> {
    let exe = std::env::current_exe().ok()?;
    let dir = exe.parent()?;
    [dir.join(name), dir.parent()?.join(name)]
        .into_iter()
        .find(|p| p.is_file())
}

/// The flag `cargo bench` passes to every bench program (ignored).
pub fn cargo_bench_flag() -> clap::Arg {
    clap::Arg::new("bench")
        .long("bench")
        .action(clap::ArgAction::SetTrue)
        .hide(true)
}

/// The value of command-line option `name` (`--axes 64`), or `default` when it is not given
/// or not a number (said on stderr).
pub fn arg_usize(name: &str, default: usize) -> usize {
    let args: Vec<String> = std::env::args().collect();
    let given = args
        .iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1));
    match given.map(|v| v.parse()) {
        Some(Ok(v)) => v,
        Some(Err(_)) => {
            eprintln!("{name}: not a number, {default} taken");
            default
        }
        None => default,
    }
}

/// Times `cycles` cycles of `n` objects with `step(object, cycle)`: ns per object and cycle.
pub fn time_cycles<T>(
    objects: &mut [T],
    k0: i64,
    cycles: usize,
    mut step: impl FnMut(&mut T, i64),
) -> f64 {
    let t0 = std::time::Instant::now();
    for c in 0..cycles as i64 {
        for o in objects.iter_mut() {
            step(o, k0 + c);
        }
    }
    t0.elapsed().as_nanos() as f64 / (cycles * objects.len().max(1)) as f64
}

/// Runs `a` and `b` once per round, `a` first in even rounds and `b` first in odd ones (so
/// neither always runs on a warm or a cold machine): their figures per round.
pub fn alternate(
    rounds: usize,
    mut a: impl FnMut(usize) -> f64,
    mut b: impl FnMut(usize) -> f64,
) -> Vec<(f64, f64)> {
    (0..rounds)
        .map(|r| {
            if r % 2 == 0 {
                let x = a(r);
                (x, b(r))
            } else {
                let y = b(r);
                (a(r), y)
            }
        })
        .collect()
}
