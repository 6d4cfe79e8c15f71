//! Every iceoryx2 port of a node's cyclic thread, opened in one place ([`Ports::open`]).

use crate::error::NodeError;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::ipc::Service;
use tandem_config::{Cell, Coupling, Leader};
use tandem_protocol::ipc::{self, IpcError, IpcNode, IpcOp};
use tandem_protocol::names;
use tandem_protocol::wire::{
    AxisTelemetry, Event, IoEvent, LeadingValueSample, NodeHealth, SignalEvent,
};
use tandem_runtime::lvgate::{gate_config, LeadingValueGate};

/// A publisher of an object's output edges or measured values.
pub(crate) type IoPublisher = Publisher<Service, IoEvent, ()>;

/// A publisher of one leader's leading values.
#[derive(Debug)]
pub(crate) struct LeaderOut {
    /// The leader: an axis or an encoder.
    pub(crate) leader: Leader,
    /// Its id on the wire (axes, then encoders).
    pub(crate) id: tandem_motion::objects::leading::LeaderId,
    /// By setpoint or actual value.
    pub(crate) coupling: Coupling,
    /// The port.
    pub(crate) port: Publisher<Service, LeadingValueSample, ()>,
}

/// A subscriber to one remote leader's leading values.
#[derive(Debug)]
pub(crate) struct LeaderIn {
    /// The leader: an axis or an encoder.
    pub(crate) leader: Leader,
    /// By setpoint or actual value.
    pub(crate) coupling: Coupling,
    /// The port.
    pub(crate) port: Subscriber<Service, LeadingValueSample, ()>,
    /// The plausibility gate every received sample passes before the buffer.
    pub(crate) gate: LeadingValueGate,
}

/// The ports of the cyclic thread. Fields drop in order: the ports before their iceoryx2 node.
#[derive(Debug)]
pub(crate) struct Ports {
    /// Leading values this node publishes: the leaders here that followers elsewhere name.
    pub(crate) leaders_out: Vec<LeaderOut>,
    /// Leading values of other nodes' leaders that followers here read.
    pub(crate) leaders_in: Vec<LeaderIn>,
    /// Notified once a cycle after the leading values are out (a gateway waits on it).
    pub(crate) published: Option<Notifier<Service>>,
    /// The telemetry snapshots: every owned axis, the node's health as header.
    pub(crate) telemetry: Publisher<Service, [AxisTelemetry], NodeHealth>,
    /// Job events and log lines.
    pub(crate) events: Publisher<Service, Event, ()>,
    /// Per output cam, cam track and measuring input of the cell (in that order): its edges or
    /// measured values, `None` for those of other nodes.
    pub(crate) io: Vec<Option<IoPublisher>>,
    /// The edges of the node's signals (inputs and outputs), if it has any.
    pub(crate) signals: Option<Publisher<Service, SignalEvent, ()>>,
    /// The node's iceoryx2 node.
    _node: IpcNode,
}

/// An error creating a port named `port`.
fn created<T, E: core::fmt::Display>(r: Result<T, E>, port: &str) -> Result<T, NodeError> {
    ipc::ctx(r, IpcOp::CreatePort, port).map_err(|e| NodeError::port(port, e))
}

/// An error opening the service of port `port`.
fn opened<T>(r: Result<T, IpcError>, port: &str) -> Result<T, NodeError> {
    r.map_err(|e| NodeError::port(port, e))
}

/// What [`Ports::open`] needs to know of the node.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PortPlan<'a> {
    /// The cell.
    pub(crate) cell: &'a Cell,
    /// The node's index.
    pub(crate) node: usize,
    /// The remote leaders the node's followers read.
    pub(crate) remote: &'a [(Leader, Coupling)],
    /// Axes in a telemetry snapshot.
    pub(crate) axes: usize,
}

impl Ports {
    /// Opens every port of node `plan.node`.
    pub(crate) fn open(plan: PortPlan<'_>) -> Result<Self, NodeError> {
        let (cell, n) = (plan.cell, plan.node);
        let me = &cell.nodes[n];
        let iox = opened(
            ipc::node(&names::node(&cell.name, &me.name), &cell.hosts[me.host]),
            "iceoryx2 node",
        )?;
        let leaders_out = Self::leaders_out(&iox, cell, n)?;
        let leaders_in = Self::leaders_in(&iox, cell, plan.remote)?;
        let published = if leaders_out.is_empty() {
            None
        } else {
            let port = "published notifier";
            let svc = opened(ipc::published(&iox, &cell.name, &me.name), port)?;
            Some(created(svc.notifier_builder().create(), port)?)
        };
        let port = "telemetry publisher";
        let svc = opened(ipc::telemetry(&iox, &cell.name, &me.name), port)?;
        let telemetry = created(
            svc.publisher_builder()
                .initial_max_slice_len(plan.axes.max(1))
                .create(),
            port,
        )?;
        let port = "event publisher";
        let svc = opened(ipc::events(&iox, &cell.name, &me.name), port)?;
        let events = created(svc.publisher_builder().max_loaned_samples(4).create(), port)?;
        let io = Self::io(&iox, cell, n)?;
        let has_signals = cell
            .signals
            .iter()
            .any(|s| cell.devices.get(s.device.0).is_some_and(|d| d.node == n));
        let signals = if has_signals {
            let port = "signal publisher";
            let svc = opened(ipc::signals(&iox, &cell.name, &me.name), port)?;
            Some(created(svc.publisher_builder().create(), port)?)
        } else {
            None
        };
        Ok(Self {
            leaders_out,
            leaders_in,
            published,
            telemetry,
            events,
            io,
            signals,
            _node: iox,
        })
    }

    /// The publishers of the leaders on node `n` that followers on other nodes name.
    fn leaders_out(iox: &IpcNode, cell: &Cell, n: usize) -> Result<Vec<LeaderOut>, NodeError> {
        let mut out: Vec<LeaderOut> = Vec::new();
        for f in cell.axes.iter().filter(|a| a.node != n) {
            for (l, c) in f.leaders.iter().flatten() {
                let (l, c) = if l.is_encoder() {
                    (*l, Coupling::Setpoint)
                } else {
                    (*l, *c)
                };
                if cell.leader_node(l) != Some(n)
                    || out.iter().any(|x| x.leader == l && x.coupling == c)
                {
                    continue;
                }
                let port = format!("publisher for {}", cell.leader_name(l));
                let svc = ipc::leading_values(
                    iox,
                    &cell.name,
                    cell.leader_name(l),
                    c == Coupling::Actual,
                    cell.leading_history(l),
                );
                let svc = opened(svc, &port)?;
                out.push(LeaderOut {
                    leader: l,
                    id: cell.leader_id(l),
                    coupling: c,
                    port: created(svc.publisher_builder().create(), &port)?,
                });
            }
        }
        Ok(out)
    }

    /// The subscribers to the remote leaders `remote`.
    fn leaders_in(
        iox: &IpcNode,
        cell: &Cell,
        remote: &[(Leader, Coupling)],
    ) -> Result<Vec<LeaderIn>, NodeError> {
        let mut out = Vec::with_capacity(remote.len());
        for &(l, c) in remote {
            let port = format!("subscriber for {}", cell.leader_name(l));
            let history = cell.leading_history(l);
            let svc = ipc::leading_values(
                iox,
                &cell.name,
                cell.leader_name(l),
                c == Coupling::Actual,
                history,
            );
            let svc = opened(svc, &port)?;
            out.push(LeaderIn {
                leader: l,
                coupling: c,
                gate: LeadingValueGate::new(gate_config(cell, l, c)),
                port: created(
                    svc.subscriber_builder().buffer_size(history).create(),
                    &port,
                )?,
            });
        }
        Ok(out)
    }

    /// The publishers of the output cams, cam tracks and measuring inputs on node `n`.
    fn io(iox: &IpcNode, cell: &Cell, n: usize) -> Result<Vec<Option<IoPublisher>>, NodeError> {
        let objects = cell
            .output_cams
            .iter()
            .map(|c| (c.name.as_str(), c.axis))
            .chain(cell.cam_tracks.iter().map(|c| (c.name.as_str(), c.axis)))
            .chain(
                cell.measuring_inputs
                    .iter()
                    .map(|c| (c.name.as_str(), c.axis)),
            );
        let mut out = Vec::new();
        for (name, axis) in objects {
            out.push(if cell.axes[axis].node == n {
                let port = format!("publisher for {name}");
                let svc = opened(ipc::io(iox, &cell.name, name), &port)?;
                Some(created(svc.publisher_builder().create(), &port)?)
            } else {
                None
            });
        }
        Ok(out)
    }
}
