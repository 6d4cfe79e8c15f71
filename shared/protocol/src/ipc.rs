//! Opening a cell's iceoryx2 services with the settings each needs. Creator and opener call
//! the same function, so their settings always agree.
//!
//! Every publish-subscribe service overflows safely (the oldest sample is dropped, so a slow
//! reader never blocks a writer; docs/processes.md, "Services").

use crate::names;
use crate::wire::{
    AxisTelemetry, CommandReply, CommandRequest, Event, IoEvent, LeadingValueSample, NodeHealth,
    SignalEvent,
};
use core::fmt;
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::{publish_subscribe, request_response};

/// An iceoryx2 node of tandem.
pub type IpcNode = Node<ipc::Service>;

/// The leading-value service of one leader.
pub type LeadingValueService = publish_subscribe::PortFactory<ipc::Service, LeadingValueSample, ()>;
/// A node's telemetry service: a slice of axes with the node's health as header.
pub type TelemetryService =
    publish_subscribe::PortFactory<ipc::Service, [AxisTelemetry], NodeHealth>;
/// A node's event service.
pub type EventService = publish_subscribe::PortFactory<ipc::Service, Event, ()>;
/// A node's signal edges.
pub type SignalService = publish_subscribe::PortFactory<ipc::Service, SignalEvent, ()>;
/// An object's output edges or measured values.
pub type IoService = publish_subscribe::PortFactory<ipc::Service, IoEvent, ()>;
/// A node's command service.
pub type CommandService =
    request_response::PortFactory<ipc::Service, CommandRequest, (), CommandReply, ()>;

/// A node's "leading values published" event service.
pub type PublishedEvent = iceoryx2::service::port_factory::event::PortFactory<ipc::Service>;

/// What tandem was doing with iceoryx2 when a call failed.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum IpcOp {
    /// Naming the iceoryx2 domain of a host.
    Domain,
    /// Naming an iceoryx2 node.
    NodeName,
    /// Creating an iceoryx2 node.
    CreateNode,
    /// Naming a service.
    ServiceName,
    /// Opening (or creating) a service.
    OpenService,
    /// Creating a port (publisher, subscriber, notifier, server) of a service.
    CreatePort,
}

/// An iceoryx2 call that failed: what was being done, to what, and iceoryx2's reason.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct IpcError {
    /// What was being done.
    pub op: IpcOp,
    /// The domain, node, service or port it concerned.
    pub name: String,
    /// iceoryx2's reason, in its words.
    pub cause: String,
}

impl fmt::Display for IpcError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (name, cause) = (&self.name, &self.cause);
        match self.op {
            IpcOp::Domain => write!(f, "iceoryx2 domain `{name}`: {cause}"),
            IpcOp::NodeName => write!(f, "node name `{name}`: {cause}"),
            IpcOp::CreateNode => write!(f, "creating iceoryx2 node `{name}`: {cause}"),
            IpcOp::ServiceName => write!(f, "service name `{name}`: {cause}"),
            IpcOp::OpenService => write!(f, "opening {name}: {cause}"),
            IpcOp::CreatePort => write!(f, "{name}: {cause}"),
        }
    }
}

impl std::error::Error for IpcError {}

/// Wraps the error of an iceoryx2 call with what was being done (`op`) to what (`name`).
pub fn ctx<T, E: fmt::Display>(r: Result<T, E>, op: IpcOp, name: &str) -> Result<T, IpcError> {
    r.map_err(|e| IpcError {
        op,
        name: name.to_owned(),
        cause: e.to_string(),
    })
}

/// The iceoryx2 configuration of host `host`'s domain ([`names::domain`]).
pub fn config(host: &str) -> Result<Config, IpcError> {
    // iceoryx2 warns on stdout that it runs on its default config: that is intended.
    set_log_level(LogLevel::Error);
    let mut c = Config::global_config().clone();
    let domain = names::domain(host);
    c.global.prefix = ctx(FileName::new(domain.as_bytes()), IpcOp::Domain, &domain)?;
    Ok(c)
}

/// Creates an iceoryx2 node named `name` in the domain of host `host`. Signals are left to the
/// process (tandem handles SIGINT/SIGTERM itself).
pub fn node(name: &str, host: &str) -> Result<IpcNode, IpcError> {
    let config = config(host)?;
    let node_name = ctx(NodeName::new(name), IpcOp::NodeName, name)?;
    ctx(
        NodeBuilder::new()
            .config(&config)
            .name(&node_name)
            .signal_handling_mode(SignalHandlingMode::Disabled)
            .create::<ipc::Service>(),
        IpcOp::CreateNode,
        name,
    )
}

/// Removes what crashed processes of host `host` left behind (their nodes' ports and services).
/// Returns how many dead nodes were cleaned.
pub fn cleanup_dead_nodes(host: &str) -> usize {
    let Ok(config) = config(host) else {
        return 0;
    };
    let mut cleaned = 0;
    // Best effort: a domain that cannot be listed has nothing this process could clean.
    let _ = Node::<ipc::Service>::list(&config, |state| {
        if let NodeState::Dead(view) = state {
            if view.try_remove_stale_resources().is_ok() {
                cleaned += 1;
            }
        }
        CallbackProgression::Continue
    });
    cleaned
}

fn service_name(s: &str) -> Result<ServiceName, IpcError> {
    ctx(ServiceName::new(s), IpcOp::ServiceName, s)
}

/// A publish-subscribe service of `T` named `name`: `history` samples for late joiners,
/// subscriber buffers up to `buffer`, safe overflow.
fn pubsub<T: core::fmt::Debug + ZeroCopySend>(
    node: &IpcNode,
    name: &str,
    history: usize,
    buffer: usize,
) -> Result<publish_subscribe::PortFactory<ipc::Service, T, ()>, IpcError> {
    ctx(
        node.service_builder(&service_name(name)?)
            .publish_subscribe::<T>()
            .history_size(history)
            .subscriber_max_buffer_size(buffer)
            .enable_safe_overflow(true)
            .max_publishers(4)
            .max_subscribers(32)
            .max_nodes(32)
            .open_or_create(),
        IpcOp::OpenService,
        name,
    )
}

/// The leading values of `leader`, keeping `history` samples for late joiners and readers.
pub fn leading_values(
    node: &IpcNode,
    cell: &str,
    leader: &str,
    actual: bool,
    history: usize,
) -> Result<LeadingValueService, IpcError> {
    pubsub(
        node,
        &names::leading_value(cell, leader, actual),
        history,
        history,
    )
}

/// The per-cycle telemetry snapshots of `node_name`.
pub fn telemetry(
    node: &IpcNode,
    cell: &str,
    node_name: &str,
) -> Result<TelemetryService, IpcError> {
    let name = names::telemetry(cell, node_name);
    ctx(
        node.service_builder(&service_name(&name)?)
            .publish_subscribe::<[AxisTelemetry]>()
            .user_header::<NodeHealth>()
            .history_size(1)
            // Observers want the newest snapshot: a few buffered ones are enough, and each
            // one is a whole node (136 B per axis) in shared memory.
            .subscriber_max_buffer_size(4)
            .enable_safe_overflow(true)
            .max_publishers(4)
            .max_subscribers(8)
            .max_nodes(32)
            .open_or_create(),
        IpcOp::OpenService,
        &name,
    )
}

/// The job events and log lines of `node_name`.
pub fn events(node: &IpcNode, cell: &str, node_name: &str) -> Result<EventService, IpcError> {
    pubsub(node, &names::events(cell, node_name), 0, 1024)
}

/// The edges of `node_name`'s signals (inputs and outputs of its process image).
pub fn signals(node: &IpcNode, cell: &str, node_name: &str) -> Result<SignalService, IpcError> {
    pubsub(node, &names::signals(cell, node_name), 0, 1024)
}

/// The output edges or measured values of object `object`.
pub fn io(node: &IpcNode, cell: &str, object: &str) -> Result<IoService, IpcError> {
    pubsub(node, &names::io(cell, object), 16, 256)
}

/// Requests one client (a gateway, `tandem cmd`) may have unanswered on a node's command
/// service at once.
pub const COMMANDS_IN_FLIGHT: usize = 16;

/// The command service of `node_name`.
pub fn commands(node: &IpcNode, cell: &str, node_name: &str) -> Result<CommandService, IpcError> {
    let name = names::commands(cell, node_name);
    ctx(
        node.service_builder(&service_name(&name)?)
            .request_response::<CommandRequest, CommandReply>()
            .max_active_requests_per_client(COMMANDS_IN_FLIGHT)
            .max_clients(16)
            .max_servers(2)
            .max_nodes(32)
            .open_or_create(),
        IpcOp::OpenService,
        &name,
    )
}

/// The event `node_name` notifies once per cycle after publishing its leading values.
pub fn published(node: &IpcNode, cell: &str, node_name: &str) -> Result<PublishedEvent, IpcError> {
    let name = names::published(cell, node_name);
    ctx(
        node.service_builder(&service_name(&name)?)
            .event()
            .max_notifiers(4)
            .max_listeners(8)
            .max_nodes(32)
            .open_or_create(),
        IpcOp::OpenService,
        &name,
    )
}
