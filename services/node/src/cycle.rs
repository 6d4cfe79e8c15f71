//! The cyclic executive: one loop over the named stages of a cycle, in this order —
//! [`NodeCycle::receive`] (leading values in), [`NodeCycle::commands`] (queued commands and due
//! script entries), [`NodeCycle::step`] (the technology objects), [`NodeCycle::publish`]
//! (leading values, the published event, output edges and measured values, job events, log
//! lines) and [`NodeCycle::record`] (telemetry, trace row, timing). Nothing here allocates,
//! locks, formats for `tracing` or blocks; a result the cycle cannot act on is counted in the
//! node's health ([`NodeHealth`]), never dropped unseen.

use crate::commands::{Done, Queued};
use crate::logring::{DiagRecord, LogRing, Record, TextWriter};
use crate::owns;
use crate::ports::Ports;
use crate::recorder::{Lost, RowPool, Wake};
use crate::report::{cpu_time_ns, Report};
use std::io::Write as _;
use std::sync::mpsc::{Receiver, SyncSender};
use tandem_config::script::ScriptEntry;
use tandem_config::{AxisIndex, Cell};
use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::objects::action::Action;
use tandem_motion::objects::axis::{axis_parameter, AxisStatus, Command};
use tandem_protocol::wire::{
    job_code, AxisTelemetry, CommandReply, Event, IoEvent, LeadingValueSample, NodeHealth,
    SignalEvent, Text, EVENT_JOB, EVENT_LOG, IO_MEASURED, IO_OUTPUT, OUTCOME_ACCEPTED,
    OUTCOME_REJECTED, SIGNAL_FLOAT, SIGNAL_INPUT, SIGNAL_INTEGER, SIGNAL_LATE, SIGNAL_TIMESTAMPED,
};
use tandem_rt as rt;
use tandem_runtime::exec::{Applied, Describe, Executive, JobNote, SignalValue};

/// The cyclic thread's links to the node's other threads.
#[derive(Debug)]
pub(crate) struct Links {
    /// Commands from the command thread.
    pub(crate) commands: Receiver<Queued>,
    /// Their results, back to the command thread.
    pub(crate) done: SyncSender<Done>,
    /// Log lines and job events, to the recorder thread (which emits them through `tracing`),
    /// and changed retained data (which it stores).
    pub(crate) diag: SyncSender<Record>,
    /// Trace rows, when a trace is written.
    pub(crate) rows: Option<RowPool>,
    /// What the recorder could not write to the disk (copied into the health).
    pub(crate) lost: std::sync::Arc<Lost>,
    /// Wakes the recorder before its channels fill (it sleeps its idle turns).
    pub(crate) wake: Wake,
}

/// Where the node's cycles lie on the cell clock.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Clock {
    /// The cell clock's time of cycle 0 (ns).
    pub(crate) epoch: i64,
    /// The node's cycle (ns).
    pub(crate) cycle: i64,
    /// The first cycle to run.
    pub(crate) first: i64,
    /// The engine time after which the node stops, if any.
    pub(crate) end_ns: Option<i64>,
}

impl Clock {
    /// The clock of a node with cycle `cycle` on `epoch`, starting at the next cycle on the
    /// grid at least 2 cycles from now.
    pub(crate) fn starting_now(epoch: i64, cycle: i64, end_ns: Option<i64>) -> Self {
        let first = ((rt::now_ns() - epoch + 2 * cycle).max(0) + cycle - 1) / cycle;
        Self {
            epoch,
            cycle,
            first,
            end_ns,
        }
    }
}

/// Job events a cycle keeps for the recorder until their axes' alarms are read.
const JOB_EVENTS: usize = 256;

/// What the cycle works on.
pub(crate) struct NodeCycle<'c> {
    exec: Executive<'c>,
    ports: Ports,
    owned: Vec<usize>,
    names: Vec<&'c str>,
    script: &'c [ScriptEntry],
    /// Per script entry: whether this node hosts its object (looked up once, not per cycle).
    mine: Vec<bool>,
    /// The next script entry.
    next: usize,
    log: LogRing,
    links: Links,
    /// This cycle's job events, for the recorder (capacity [`JOB_EVENTS`]).
    jobs: Vec<Event>,
    health: NodeHealth,
    report: Report,
    /// Per signal of the cell: its device, channel and whether it is timestamped (to name an
    /// output switch's signal without searching the cell's names).
    signals: Vec<(usize, u8, bool)>,
    /// Per signal of the cell: whether it is an input (a float output set by `SetOutput`
    /// reports its change as an input's does, without the input flag).
    signal_inputs: Vec<bool>,
    /// The node's EtherCAT segment, if it has one.
    ethercat: Option<crate::ethercat::Link>,
}

/// What [`NodeCycle::new`] takes.
pub(crate) struct CycleParts<'c> {
    /// The cell.
    pub(crate) cell: &'c Cell,
    /// The node's index.
    pub(crate) node: usize,
    /// Its technology objects.
    pub(crate) exec: Executive<'c>,
    /// Its ports.
    pub(crate) ports: Ports,
    /// The axes it owns.
    pub(crate) owned: Vec<usize>,
    /// The script's entries (all objects; the node applies its own).
    pub(crate) script: &'c [ScriptEntry],
    /// Its links to the other threads.
    pub(crate) links: Links,
    /// Cycles between two telemetry snapshots.
    pub(crate) telemetry_every: u64,
    /// The node's EtherCAT segment, in OP, if it has one.
    pub(crate) ethercat: Option<crate::ethercat::Link>,
}

impl<'c> NodeCycle<'c> {
    /// The cycle of a node about to run on `clock`.
    pub(crate) fn new(p: CycleParts<'c>, clock: &Clock) -> Self {
        let health = NodeHealth {
            epoch_ns: clock.epoch,
            cycle_ns: clock.cycle,
            pid: std::process::id(),
            axes: p.owned.len() as u32,
            telemetry_every: p.telemetry_every.max(1),
            ..NodeHealth::default()
        };
        let next = p
            .script
            .partition_point(|e| e.t_ns < clock.first * clock.cycle);
        let mine = p
            .script
            .iter()
            .map(|e| owns(p.cell, p.node, &e.axis, &e.action))
            .collect();
        Self {
            exec: p.exec,
            ports: p.ports,
            owned: p.owned,
            names: p.cell.object_names(),
            script: p.script,
            mine,
            next,
            log: LogRing::new(),
            links: p.links,
            jobs: Vec::with_capacity(JOB_EVENTS),
            health,
            report: Report::default(),
            signals: p
                .cell
                .signals
                .iter()
                .map(|s| {
                    let ts = s.signal_type == tandem_config::SignalType::TimestampedBool;
                    (s.device.0, s.channel, ts)
                })
                .collect(),
            signal_inputs: p
                .cell
                .signals
                .iter()
                .map(|s| s.direction == tandem_config::SignalDirection::Input)
                .collect(),
            ethercat: p.ethercat,
        }
    }

    /// Script entries for this node's objects before the first cycle (they are skipped).
    pub(crate) fn skipped(&self) -> usize {
        self.mine[..self.next].iter().filter(|m| **m).count()
    }

    /// Leaders published and remote leaders followed.
    pub(crate) fn links_count(&self) -> (usize, usize) {
        (self.ports.leaders_out.len(), self.ports.leaders_in.len())
    }

    /// Runs cycles on `clock` until SIGINT/SIGTERM or the end; returns what it measured and
    /// the node's health at the end.
    pub(crate) fn run(mut self, clock: &Clock) -> (Report, NodeHealth) {
        let mut k = clock.first;
        // The run is measured from the start of its first cycle.
        let started = clock.epoch + k * clock.cycle;
        let mut cpu0 = None;
        loop {
            let t = k * clock.cycle;
            if clock.end_ns.is_some_and(|e| t > e) || rt::termination_requested() {
                break;
            }
            let start = clock.epoch + t;
            rt::sleep_until(start);
            let wake = rt::now_ns();
            if wake < start {
                // A signal woke us early: look at the flag, then sleep again.
                continue;
            }
            if let Some(to) = rejoin(clock, k, wake) {
                // Stalled: the loop's next pass runs grid cycle `to` at once (its start is past).
                self.skip_cycles(to - k, wake - start, to * clock.cycle);
                k = to;
                continue;
            }
            if cpu0.is_none() {
                cpu0 = Some((cpu_time_ns(), rt::thread_cpu_ns()));
            }
            let mut marks = [wake; 5];
            self.receive(wake - clock.epoch);
            marks[1] = rt::now_ns();
            self.commands(t);
            if let Some(segment) = self.ethercat.as_mut() {
                // The PDI at the boundary `t`: inputs of the exchange started at `t - cycle`
                // in, the outputs of the last step out (crate::ethercat).
                segment.exchange(t, &mut self.exec, &mut self.log);
            }
            marks[2] = rt::now_ns();
            self.step(t);
            marks[3] = rt::now_ns();
            self.publish(t);
            marks[4] = rt::now_ns();
            self.record(t, start, &marks, clock.cycle);
            k += 1;
        }
        if self.health.cycles > 0 {
            // The end state for observers, whatever the telemetry rate.
            self.telemetry();
        }
        self.hand_over_last_adjustments();
        if let Some(segment) = &self.ethercat {
            segment.report();
        }
        self.report.wall_ns = rt::now_ns() - started;
        if let Some((process, thread)) = cpu0 {
            self.report.cpu_ns = cpu_time_ns() - process;
            self.report.cyclic_cpu_ns = rt::thread_cpu_ns() - thread;
        }
        self.health.extrapolated = self.exec.extrapolated;
        self.health.lv_lost = self.exec.leading_lost();
        (self.report, self.health)
    }

    /// Receive: the samples other nodes published pass their leader's plausibility gate
    /// (receiver's clock `now`, engine time) and go into their leaders' buffers; refusals are
    /// counted by kind.
    fn receive(&mut self, now: i64) {
        for x in &mut self.ports.leaders_in {
            while let Ok(Some(sample)) = x.port.receive() {
                let s = sample.payload().to_sample();
                let fed = x.gate.check(now, &s).is_ok()
                    && self.exec.feed(x.leader, x.coupling, s).is_ok();
                self.health.samples_rejected += u64::from(!fed);
            }
        }
        crate::lvhealth::count(&self.ports.leaders_in, &mut self.health);
    }

    /// Commands: the queued commands, each answered, then the script entries due at `t`.
    fn commands(&mut self, t: i64) {
        while let Ok(q) = self.links.commands.try_recv() {
            let e = &q.entry;
            let applied = self
                .exec
                .apply(t, &e.axis, e.instruction, e.action, &mut self.log)
                .unwrap_or(Err(ErrorId::IllegalObject));
            let mut reply = reply(t, applied);
            if applied.is_ok() {
                parameter_reply(&self.exec, e, &mut reply);
            }
            if self.links.done.try_send(Done { id: q.id, reply }).is_err() {
                self.health.commands_unanswered += 1;
            }
        }
        while let Some(e) = self.script.get(self.next).filter(|e| e.t_ns <= t) {
            let mine = self.mine.get(self.next).copied().unwrap_or(false);
            self.next += 1;
            if mine {
                let r =
                    self.exec
                        .apply_at(t, e.t_ns, &e.axis, e.instruction, e.action, &mut self.log);
                if !matches!(r, Ok(Ok(_))) {
                    self.health.script_rejected += 1;
                }
            }
        }
    }

    /// Step: the technology objects, as `tandem sim` steps them. When the record stage reads
    /// every status after it (a telemetry snapshot, a trace row), the step copies each axis'
    /// status while the axis is in the caches.
    fn step(&mut self, t: i64) {
        let h = &self.health;
        if h.cycles % h.telemetry_every.max(1) == 0 || self.links.rows.is_some() {
            self.exec.want_status();
        }
        if self.exec.step(t, &mut self.log).is_err() {
            self.health.step_errors += 1;
        }
    }

    /// Publish: leading values, the published event, output edges and measured values, job
    /// events and log lines (these two also to the recorder), changed retained data (to the
    /// recorder).
    fn publish(&mut self, t: i64) {
        let mut failed = 0u64;
        // The sequence number is the cycle on the cell clock (docs/processes.md, "Refused samples").
        let seq = u64::try_from(t / self.health.cycle_ns.max(1)).unwrap_or(0);
        for x in &mut self.ports.leaders_out {
            let s = self.exec.sample(x.leader, x.coupling, t, seq);
            let sample = LeadingValueSample::from_sample(x.id, &s);
            failed += u64::from(x.port.send_copy(sample).is_err());
        }
        if let Some(n) = &self.ports.published {
            failed += u64::from(n.notify().is_err());
        }
        let io = &self.ports.io;
        self.exec.drain_io_notes(|x| {
            if let Some(Some(p)) = io.get(x.object) {
                let ev = IoEvent {
                    t_ns: x.t_ns,
                    kind: if x.measured { IO_MEASURED } else { IO_OUTPUT },
                    counter: x.counter,
                    value: x.value,
                };
                failed += u64::from(p.send_copy(ev).is_err());
            }
        });
        failed += self.publish_signals();
        let (events, names, jobs) = (&self.ports.events, &self.names, &mut self.jobs);
        let mut dropped = 0u64;
        self.exec.drain_job_notes(|j| {
            let ev = job_event(j, names);
            failed += u64::from(events.send_copy(ev).is_err());
            // Within the capacity the buffer was made with: no allocation.
            if jobs.len() < jobs.capacity() {
                jobs.push(ev);
            } else {
                dropped += 1;
            }
        });
        self.health.sends_failed += failed;
        self.health.diag_dropped += dropped;
        self.hand_over_jobs();
        self.hand_over_log(t);
        self.hand_over_adjustments();
    }

    /// The edges of the node's signals since the last cycle (inputs as sampled, outputs as
    /// switched), one fixed-size record each; returns the sends that failed.
    fn publish_signals(&mut self) -> u64 {
        let Some(port) = &self.ports.signals else {
            return 0;
        };
        let mut failed = 0u64;
        let signals = &self.signals;
        self.exec.drain_input_edges(|e| {
            let ts = signals.get(e.signal).is_some_and(|s| s.2);
            let ev = SignalEvent {
                t_ns: e.time_ns,
                ref_ns: e.sampled_ns,
                signal: e.signal as u32,
                level: u32::from(e.rising),
                flags: SIGNAL_INPUT | if ts { SIGNAL_TIMESTAMPED } else { 0 },
                reserved: 0,
                value: if e.rising { 1.0 } else { 0.0 },
            };
            failed += u64::from(port.send_copy(ev).is_err());
        });
        self.exec.drain_output_switches(|x| {
            let Some(k) = signals
                .iter()
                .position(|s| s.0 == x.device && s.1 == x.channel)
            else {
                return;
            };
            let ts = signals.get(k).is_some_and(|s| s.2);
            let ev = SignalEvent {
                t_ns: x.time_ns,
                ref_ns: x.edge_ns,
                signal: k as u32,
                level: u32::from(x.on),
                flags: if ts { SIGNAL_TIMESTAMPED } else { 0 }
                    | if x.late { SIGNAL_LATE } else { 0 },
                reserved: 0,
                value: if x.on { 1.0 } else { 0.0 },
            };
            failed += u64::from(port.send_copy(ev).is_err());
        });
        let inputs = &self.signal_inputs;
        self.exec.drain_input_values(|e| {
            // A float output set by `SetOutput` comes this way too, without the input flag.
            let input = inputs.get(e.signal).copied().unwrap_or(true);
            let (flags, value) = match e.value {
                SignalValue::Integer(v) => (SIGNAL_INTEGER, v as f64),
                SignalValue::Float(v) => (SIGNAL_FLOAT, v),
            };
            let ev = SignalEvent {
                t_ns: e.sampled_ns,
                ref_ns: e.sampled_ns,
                signal: e.signal as u32,
                level: u32::from(value != 0.0),
                flags: if input { SIGNAL_INPUT } else { 0 } | flags,
                reserved: 0,
                value,
            };
            failed += u64::from(port.send_copy(ev).is_err());
        });
        failed
    }

    /// Hands the axes' changed retained data (absolute encoder adjustments) to the recorder,
    /// which stores it. A change the full channel refuses is counted and offered again the
    /// next cycle, so the newest is always stored in the end.
    fn hand_over_adjustments(&mut self) {
        let (diag, dropped) = (&self.links.diag, &mut self.health.diag_dropped);
        let mut any = false;
        self.exec.take_adjustments(|c| {
            let sent = diag.try_send(Record::Retain(c)).is_ok();
            *dropped += u64::from(!sent);
            any |= sent;
            sent
        });
        if any {
            // Retained data is stored at once, not at the recorder's next idle turn.
            self.links.wake.now();
        }
    }

    /// After the last cycle (off the cyclic path): hands over what the last cycles could not,
    /// waiting for room; the recorder drains the channel until the node stops.
    fn hand_over_last_adjustments(&mut self) {
        let diag = &self.links.diag;
        // `send` fails only when the recorder is gone: then nothing can store it.
        self.exec
            .take_adjustments(|c| diag.send(Record::Retain(c)).is_ok());
    }

    /// Hands this cycle's job events to the recorder, each with its axis' pending alarm.
    fn hand_over_jobs(&mut self) {
        for event in self.jobs.drain(..) {
            // Only these axes' status is read (copying every axis' would cost each cycle).
            let alarm = self
                .exec
                .axis_status(AxisIndex(event.object as usize))
                .map_or(0, |s| s.error_detail.number);
            if self
                .links
                .diag
                .try_send(Record::Diag(DiagRecord { event, alarm }))
                .is_err()
            {
                self.health.diag_dropped += 1;
            }
            self.links.wake.records(1);
        }
    }

    /// Publishes the log ring's lines and hands them to the recorder.
    fn hand_over_log(&mut self, t: i64) {
        while let Some(line) = self.log.lines.pop_front() {
            let event = Event {
                t_ns: t,
                kind: EVENT_LOG,
                object: u32::MAX,
                job: 0,
                code: 0,
                error_id: 0,
                message: line,
            };
            if self.ports.events.send_copy(event).is_err() {
                self.health.sends_failed += 1;
            }
            if self
                .links
                .diag
                .try_send(Record::Diag(DiagRecord { event, alarm: 0 }))
                .is_err()
            {
                self.health.diag_dropped += 1;
            }
            self.links.wake.records(1);
        }
    }

    /// Record: the health, the telemetry snapshot, the trace row and the cycle's timing.
    fn record(&mut self, t: i64, start: i64, marks: &[i64; 5], cycle: i64) {
        let wake = marks[0];
        let lateness = wake - start;
        let h = &mut self.health;
        h.t_ns = t;
        h.lateness_ns = lateness;
        h.max_lateness_ns = h.max_lateness_ns.max(lateness);
        h.cycles += 1;
        h.extrapolated = self.exec.extrapolated;
        h.lv_lost = self.exec.leading_lost();
        h.log_dropped = self.log.dropped + self.exec.notes_dropped;
        self.links.lost.copy_into(h);
        if (h.cycles - 1) % h.telemetry_every == 0 {
            self.telemetry();
        }
        if let Some(pool) = &self.links.rows {
            self.health.trace_dropped += u64::from(!row(pool, t, &self.owned, self.exec.status()));
            self.links.wake.rows(1);
        }
        let end = rt::now_ns();
        let compute = end - wake;
        let h = &mut self.health;
        h.compute_ns = compute;
        h.max_compute_ns = h.max_compute_ns.max(compute);
        self.report.compute.record(compute);
        self.report.stages.add(marks, end);
        self.report.lateness.record(lateness);
        self.report.cycles += 1;
        if end > start + cycle {
            h.overruns += 1;
            self.report.overruns += 1;
        }
    }

    /// The node woke `late` ns after its cycle's start and skips `n` cycles to rejoin the time
    /// grid at engine time `t`: counted in the health, and said once per stall in the log (an
    /// S7-1500 calls this a cycle overflow). No allocation: the line is formatted into the log
    /// ring's buffer.
    fn skip_cycles(&mut self, n: i64, late: i64, t: i64) {
        let n = u64::try_from(n).unwrap_or(0);
        self.health.skipped_cycles += n;
        // The log ring never fails: a line beyond its capacity is counted as dropped.
        let _ = writeln!(
            self.log,
            "t={} cycle overflow: woke {} late, skipped {n} cycles to rejoin the time grid \
             ({} skipped so far)",
            tandem_runtime::exec::Secs(t),
            tandem_runtime::exec::Secs(late),
            self.health.skipped_cycles
        );
    }

    /// Publishes a telemetry snapshot: every owned axis, the health as header.
    fn telemetry(&mut self) {
        let status = self.exec.status();
        let owned = &self.owned;
        let Ok(mut sample) = self.ports.telemetry.loan_slice_uninit(owned.len()) else {
            self.health.sends_failed += 1;
            return;
        };
        *sample.user_header_mut() = self.health;
        let sample = sample.write_from_fn(|i| {
            owned
                .get(i)
                .map(|a| AxisTelemetry::from_status(*a as u32, &status[*a]))
                .unwrap_or_default()
        });
        if sample.send().is_err() {
            self.health.sends_failed += 1;
        }
    }
}

/// How late a cycle may wake before the node skips to the current grid cycle instead of
/// running every missed cycle back to back: 100 ms, or 2 cycles of a slower node. Below it the
/// missed cycles are replayed (the motion stays exactly as on an idle machine; the leading
/// values' tolerance decides whether remote followers bridged the gap); above it replaying
/// would only prolong the lateness (docs/processes.md, "Stalls").
pub(crate) const REJOIN_AFTER_NS: i64 = 100_000_000;

/// The grid cycle to continue with when cycle `k` of `clock` woke at `wake` (cell clock, ns)
/// more than [`REJOIN_AFTER_NS`] (at least 2 cycles) after its start: the last cycle whose
/// start is not after `wake`. `None`: run cycle `k`.
pub(crate) fn rejoin(clock: &Clock, k: i64, wake: i64) -> Option<i64> {
    let cycle = clock.cycle.max(1);
    let start = clock.epoch.saturating_add(k.saturating_mul(cycle));
    let late = wake.saturating_sub(start);
    if late <= REJOIN_AFTER_NS.max(cycle.saturating_mul(2)) {
        return None;
    }
    let to = wake.saturating_sub(clock.epoch).div_euclid(cycle);
    (to > k).then_some(to)
}

/// Fills a trace row from the pool and hands it to the recorder; `false` when the recorder
/// was behind (no free row, or its queue full) and the row is dropped.
fn row(pool: &RowPool, t: i64, owned: &[usize], status: &[AxisStatus]) -> bool {
    let Ok((_, mut row)) = pool.free.try_recv() else {
        return false;
    };
    // Within the capacity the row was made with: no allocation.
    row.clear();
    row.extend(owned.iter().map(|a| status[*a]));
    pool.full.try_send((t, row)).is_ok()
}

/// The reply to a command applied at `t`.
fn reply(t: i64, applied: Applied) -> CommandReply {
    let mut reply = CommandReply {
        outcome: OUTCOME_ACCEPTED,
        job: 0,
        error_id: 0,
        t_ns: t,
        message: Text::default(),
    };
    match applied {
        Ok(job) => reply.job = job.unwrap_or(0),
        Err(id) => {
            reply.outcome = OUTCOME_REJECTED;
            reply.error_id = u32::from(id.code());
            reply.message = Text::new(id.description());
        }
    }
    reply
}

/// MC_ReadParameter's and MC_WriteParameter's reply carries the value the axis has now:
/// `DynamicLimits.MaxJerk = 50000` (formatted into the fixed text, no allocation).
fn parameter_reply(exec: &Executive<'_>, e: &ScriptEntry, reply: &mut CommandReply) {
    let n = match e.action {
        Action::Command(
            Command::ReadParameter { parameter } | Command::WriteParameter { parameter, .. },
        ) => parameter,
        _ => return,
    };
    let name = axis_parameter(n).map_or("?", |p| p.key);
    if let Ok(value) = exec.read_parameter(&e.axis, n) {
        // A TextWriter never fails: it cuts the text at its capacity.
        let _ = core::fmt::Write::write_fmt(
            &mut TextWriter(&mut reply.message),
            format_args!("{name} = {value}"),
        );
    }
}

/// The event of a job note, its message formatted into the fixed text (no allocation).
fn job_event(j: &JobNote, names: &[&str]) -> Event {
    let (code, error_id) = job_code(j.kind);
    let mut ev = Event {
        t_ns: j.t_ns,
        kind: EVENT_JOB,
        object: j.object as u32,
        job: j.job,
        code,
        error_id,
        message: Text::default(),
    };
    // A TextWriter never fails: it cuts the text at its capacity.
    let _ = core::fmt::Write::write_fmt(
        &mut TextWriter(&mut ev.message),
        format_args!(
            "{} {} job {}: {}",
            names.get(j.object).copied().unwrap_or("?"),
            j.instruction.name(),
            j.job,
            Describe(j.kind)
        ),
    );
    ev
}

#[cfg(test)]
mod tests {
    use super::{rejoin, Clock, REJOIN_AFTER_NS};

    const MS: i64 = 1_000_000;

    fn clock(cycle: i64) -> Clock {
        Clock {
            epoch: 5_000 * MS,
            cycle,
            first: 0,
            end_ns: None,
        }
    }

    /// A cycle on time, or late by one or a few cycles, runs as today: every cycle, no skip.
    #[test]
    fn jitter_and_plain_overruns_run_every_cycle() {
        let c = clock(MS);
        let start = c.epoch + 7 * MS;
        for late in [0, MS / 2, MS, 2 * MS + 1, 37 * MS, REJOIN_AFTER_NS] {
            assert_eq!(rejoin(&c, 7, start + late), None, "late {late} ns");
        }
    }

    /// A stall of 2 s on a 1 ms cycle continues with the grid cycle of the wake-up: 2,000
    /// cycles skipped, the cycle run is late by less than one cycle.
    #[test]
    fn a_stall_rejoins_the_grid_cycle_of_the_wake_up() {
        let c = clock(MS);
        let start = c.epoch + 7 * MS;
        let wake = start + 2_000 * MS + 300_000;
        let to = rejoin(&c, 7, wake).unwrap_or(7);
        assert_eq!(to - 7, 2_000);
        let late = wake - (c.epoch + to * MS);
        assert!((0..MS).contains(&late), "{late}");
        // Just over the threshold: skips too.
        assert_eq!(rejoin(&c, 7, start + REJOIN_AFTER_NS + 1), Some(107));
    }

    /// A slow node (100 ms cycle) replays a one-cycle overrun and skips only beyond 2 cycles.
    #[test]
    fn a_slow_node_skips_only_beyond_two_cycles() {
        let c = clock(100 * MS);
        let start = c.epoch + 3 * 100 * MS;
        assert_eq!(rejoin(&c, 3, start + 150 * MS), None);
        assert_eq!(rejoin(&c, 3, start + 200 * MS), None);
        assert_eq!(rejoin(&c, 3, start + 250 * MS), Some(5));
    }
}
