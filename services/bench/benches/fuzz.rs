//! Fuzzing every decoder of outside input (docs/fuzzing.md): leading values and key
//! expressions from Zenoh, JSON and text commands, cell and script files, cam CSV.
//!
//! `cargo bench -p tandem-bench --bench fuzz -- --inputs 10000000 --seed 1` feeds 10^7
//! generated inputs from seed 1, shared evenly by the targets, and prints per target the
//! inputs, the accepted ones, the failures (panics, wrong answers, each with its reproduction),
//! the hangs (over 1 s twice), the stalls (over 1 s once: the thread was preempted), the
//! slowest input (and its time fed again alone) and the rate. `--target cell` (repeatable) runs one
//! target; `--index N` feeds one input and prints it, to reproduce a failure. An input that
//! does not return within 10 s is reported by a watchdog, which then ends the run (exit 2).
//! Exit 1 when anything failed.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use clap::{value_parser, Arg, ArgAction, Command};
use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::{Duration, Instant};
use tandem_bench::fuzz::{self, Fixture, Plan, Target, Watch};

/// An input this slow is taken for an endless loop.
const WATCHDOG: Duration = Duration::from_secs(10);

fn main() {
    let m = Command::new("fuzz")
        .about("Feeds generated inputs to every decoder of outside input")
        .arg(
            Arg::new("seed")
                .long("seed")
                .value_parser(value_parser!(u64))
                .default_value("1"),
        )
        .arg(
            Arg::new("inputs")
                .long("inputs")
                .value_parser(value_parser!(u64))
                .default_value("100000"),
        )
        .arg(
            Arg::new("target")
                .long("target")
                .action(ArgAction::Append)
                .value_parser(Target::ALL.map(Target::name)),
        )
        .arg(
            Arg::new("index")
                .long("index")
                .value_parser(value_parser!(u64)),
        )
        .arg(tandem_bench::cargo_bench_flag())
        .get_matches();
    let seed: u64 = *m.get_one("seed").unwrap();
    let inputs: u64 = *m.get_one("inputs").unwrap();
    let targets: Vec<Target> = match m.get_many::<String>("target") {
        Some(names) => names.filter_map(|n| Target::from_name(n)).collect(),
        None => Target::ALL.to_vec(),
    };
    let fixture = Fixture::new();
    if let Some(&index) = m.get_one::<u64>("index") {
        for &t in &targets {
            let input = fuzz::generate(&fixture, seed, t, index);
            println!(
                "target {t} seed {seed} index {index}: {} bytes",
                input.len()
            );
            println!("hex: {}", fuzz::hex(&input, usize::MAX));
            println!("text: {:?}", String::from_utf8_lossy(&input));
            let start = Instant::now();
            let outcome = fuzz::feed(&fixture, t, index, &input);
            println!("outcome: {outcome:?} in {:?}", start.elapsed());
        }
        return;
    }
    println!(
        "fuzz: seed {seed}, {inputs} inputs over {} targets, {} bundled cells parsed",
        targets.len(),
        fixture.cells()
    );
    let watch = Arc::new(Watch::default());
    spawn_watchdog(Arc::clone(&watch), seed);
    let start = Instant::now();
    let plan = Plan {
        seed,
        inputs,
        targets,
    };
    let reports = fuzz::run(&fixture, &plan, &watch, |f| println!("{f}"));
    let wall = start.elapsed().as_secs_f64();
    println!(
        "{:<7} {:>10} {:>10} {:>8} {:>6} {:>6} {:>12} {:>10} {:>12} {:>10}",
        "target",
        "inputs",
        "accepted",
        "failures",
        "hangs",
        "stalls",
        "slowest",
        "at index",
        "re-run",
        "inputs/s"
    );
    let mut bad = 0;
    for r in &reports {
        // The slowest input fed again alone, best of 3: on a loaded machine the slowest time
        // of the run is mostly preemption.
        let input = fuzz::generate(&fixture, seed, r.target, r.slowest_index);
        let alone = (0..3)
            .map(|_| {
                let t = Instant::now();
                // Its answer was counted in the run.
                let _ = fuzz::feed(&fixture, r.target, r.slowest_index, &input);
                t.elapsed()
            })
            .min()
            .unwrap_or_default();
        println!(
            "{:<7} {:>10} {:>10} {:>8} {:>6} {:>6} {:>10.3}ms {:>10} {:>10.3}ms {:>10.0}",
            r.target.name(),
            r.inputs,
            r.accepted,
            r.failures,
            r.hangs,
            r.stalls,
            r.slowest_ns as f64 / 1e6,
            r.slowest_index,
            alone.as_secs_f64() * 1e3,
            r.inputs as f64 / (r.total_ns.max(1) as f64 / 1e9)
        );
        bad += r.failures + r.hangs;
    }
    let total: u64 = reports.iter().map(|r| r.inputs).sum();
    println!(
        "total   {total:>10} inputs in {wall:.1} s ({:.0} inputs/s), {bad} failures and hangs",
        total as f64 / wall
    );
    if bad > 0 {
        std::process::exit(1);
    }
}

/// Reports an input that has not returned for [`WATCHDOG`] and ends the run.
fn spawn_watchdog(watch: Arc<Watch>, seed: u64) {
    std::thread::spawn(move || {
        let mut last = (u64::MAX, Instant::now());
        loop {
            std::thread::sleep(Duration::from_millis(500));
            let fed = watch.fed.load(Ordering::Relaxed);
            if fed != last.0 {
                last = (fed, Instant::now());
            } else if last.1.elapsed() > WATCHDOG {
                let (t, i) = (watch.target(), watch.index.load(Ordering::Relaxed));
                println!(
                    "HANG target {t} seed {seed} index {i}: no answer for {:?}; reproduce with `cargo bench -p tandem-bench --bench fuzz -- --target {t} --seed {seed} --index {i}`",
                    WATCHDOG
                );
                std::process::exit(2);
            }
        }
    });
}
