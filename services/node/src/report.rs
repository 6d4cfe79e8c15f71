//! What a node run measured: cycles, overruns, compute time and lateness histograms, CPU
//! time and resident memory.

/// Histogram of durations in 1 µs bins up to 50 ms (the last bin holds the rest).
#[derive(Debug, Clone)]
pub struct Histogram {
    bins: Vec<u32>,
    count: u64,
    max_ns: i64,
}

impl Default for Histogram {
    fn default() -> Self {
        Self {
            bins: vec![0; 50_001],
            count: 0,
            max_ns: 0,
        }
    }
}

impl Histogram {
    /// Records one duration.
    pub fn record(&mut self, ns: i64) {
        let i = usize::try_from(ns.max(0) / 1000)
            .unwrap_or(usize::MAX)
            .min(self.bins.len() - 1);
        self.bins[i] = self.bins[i].saturating_add(1);
        self.count += 1;
        self.max_ns = self.max_ns.max(ns);
    }

    /// The `q` quantile (0..=1) in µs (upper bin edge), or the max for `q = 1`.
    pub fn quantile_us(&self, q: f64) -> f64 {
        if self.count == 0 {
            return 0.0;
        }
        if q >= 1.0 {
            return self.max_ns as f64 / 1000.0;
        }
        let target = (q * self.count as f64).ceil().max(1.0) as u64;
        let mut seen = 0u64;
        for (i, b) in self.bins.iter().enumerate() {
            seen += u64::from(*b);
            if seen >= target {
                return (i + 1) as f64;
            }
        }
        self.max_ns as f64 / 1000.0
    }

    /// Values recorded.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// `p50/p99/p99.9/max` in µs.
    pub fn summary(&self) -> String {
        format!(
            "p50 {:.0} / p99 {:.0} / p99.9 {:.0} / max {:.1} µs",
            self.quantile_us(0.5),
            self.quantile_us(0.99),
            self.quantile_us(0.999),
            self.quantile_us(1.0)
        )
    }
}

/// What a node run measured.
#[derive(Debug, Clone, Default)]
pub struct Report {
    /// Cycles run.
    pub cycles: u64,
    /// Cycles that ended after the next one should have started.
    pub overruns: u64,
    /// Compute time per cycle.
    pub compute: Histogram,
    /// Wake-up lateness per cycle.
    pub lateness: Histogram,
    /// Wall time the cyclic thread ran (ns) and the CPU time it used (ns).
    pub wall_ns: i64,
    /// CPU time of the whole process over the run (ns).
    pub cpu_ns: i64,
    /// Resident memory at the end (bytes).
    pub resident_bytes: u64,
    /// CPU time of the cyclic thread alone over the run (ns).
    pub cyclic_cpu_ns: i64,
    /// Wall time of each stage of the cycle, summed over the run.
    pub stages: Stages,
    /// Trace rows the recorder could not write to the disk (`NodeHealth::trace_rows_lost`).
    pub trace_rows_lost: u64,
    /// Log lines the recorder could not write to the disk (`NodeHealth::log_lines_lost`).
    pub log_lines_lost: u64,
}

/// Wall time of each stage of the cycle, summed over a run (ns).
#[derive(Debug, Clone, Copy, Default)]
pub struct Stages {
    /// Leading values in.
    pub receive_ns: i64,
    /// Queued commands and due script entries.
    pub commands_ns: i64,
    /// The technology objects' step.
    pub step_ns: i64,
    /// Leading values, events, output edges and measured values out.
    pub publish_ns: i64,
    /// Health, telemetry, trace row and timing.
    pub record_ns: i64,
}

impl Stages {
    /// Adds one cycle: `marks` are the clock at the start of receive, commands, step, publish
    /// and record, `end` at the end of record.
    pub(crate) fn add(&mut self, marks: &[i64; 5], end: i64) {
        self.receive_ns += marks[1] - marks[0];
        self.commands_ns += marks[2] - marks[1];
        self.step_ns += marks[3] - marks[2];
        self.publish_ns += marks[4] - marks[3];
        self.record_ns += end - marks[4];
    }
}

/// The process' user + system CPU time (ns).
pub(crate) fn cpu_time_ns() -> i64 {
    tandem_rt::process_cpu_ns()
}
