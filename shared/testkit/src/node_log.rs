//! Reading the logs a node (or `tandem sim`) writes: every line starts with `t=<seconds> `.
//!
//! ```
//! use tandem_testkit::node_log::{log_time, missing_leader};
//!
//! let log = "t=4.990 feed MC_GearIn job 3: InGear\n\
//!            t=5.040 leading value of line missing at t - D = 5.030: \
//!            newest sample t=4.999, later than the tolerance 30 ms allows\n";
//! let missing = missing_leader(log, "line");
//! assert_eq!((missing.t, missing.newest), (5.040, 4.999));
//! assert_eq!(log_time(log.lines().next().unwrap()), 4.990);
//! ```

/// The time (s) of a log line.
///
/// # Panics
/// When the line does not start with `t=<seconds> `.
pub fn log_time(line: &str) -> f64 {
    line.get(2..)
        .and_then(|rest| rest.split(' ').next())
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("not a log line with its time: {line}"))
}

/// The first line saying that the leading value of `leader` was missing because its newest
/// sample was too old (the leader's node or link stopped).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MissingLeader<'a> {
    /// The whole line, for the failure messages.
    pub line: &'a str,
    /// When it was logged (s).
    pub t: f64,
    /// The time of the newest sample of the leader the node had then (s).
    pub newest: f64,
}

/// The first line of `log` saying that the leading value of `leader` went missing.
///
/// # Panics
/// When there is none (with the log), or it names no newest sample (with the line).
pub fn missing_leader<'a>(log: &'a str, leader: &str) -> MissingLeader<'a> {
    let line = log
        .lines()
        .find(|l| l.contains(&format!("leading value of {leader} missing")))
        .unwrap_or_else(|| panic!("{log}"));
    let newest: f64 = line
        .split("newest sample t=")
        .nth(1)
        .and_then(|x| x.split(',').next())
        .and_then(|x| x.parse().ok())
        .unwrap_or_else(|| panic!("{line}"));
    MissingLeader {
        line,
        t: log_time(line),
        newest,
    }
}
