//! `tandem ethercat scan <interface>`: what is on an EtherCAT segment, for writing the cell
//! file. ethercrab (unmodified) is the MainDevice: it counts the SubDevices, reads their SII
//! (identity, name), brings them to PRE-OP and maps their process data, so the table shows
//! each SubDevice's position, configured address, identity, name, input and output sizes and
//! distributed clock support. The segment is left in PRE-OP.

use std::io::Write;
use std::time::Duration;

use ethercrab::std::{ethercat_now, tx_rx_task};
use ethercrab::{MainDevice, MainDeviceConfig, PduStorage, Timeouts};

use crate::error::CliError;

/// SubDevices a scan can list.
const MAX_SUBDEVICES: usize = 64;
/// Process data a scan can map (bytes).
const MAX_PDI: usize = 4096;
/// Frames in flight and their size.
const MAX_FRAMES: usize = 16;
const MAX_PDU_DATA: usize = PduStorage::element_size(1100);
/// The whole scan must finish within this (ethercrab's own timeouts are shorter).
const SCAN_TIMEOUT: Duration = Duration::from_secs(60);
/// How long a frame may take to come back. ethercrab's default is 30 ms; a scan is not
/// cyclic, and a busy host (or an emulated segment on one) must not fail it: a reply later
/// than this ends ethercrab's receive task.
const PDU_TIMEOUT: Duration = Duration::from_millis(500);
/// Drift compensation frames at init: enough for a listing, far fewer than ethercrab's
/// default 10,000 (a scan does not run synchronised).
const DC_ITERATIONS: u32 = 100;

/// One SubDevice as a scan lists it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ScannedSubDevice {
    /// Position in the segment (0 first).
    pub position: usize,
    /// Configured station address.
    pub address: u16,
    /// Vendor ID.
    pub vendor: u32,
    /// Product code.
    pub product: u32,
    /// Revision.
    pub revision: u32,
    /// Serial number.
    pub serial: u32,
    /// Name (the SII order string).
    pub name: String,
    /// Input bytes (TxPDOs).
    pub inputs: usize,
    /// Output bytes (RxPDOs).
    pub outputs: usize,
    /// Distributed clock support as ethercrab classifies it (`None`, `RefOnly`, `Bits32`,
    /// `Bits64`).
    pub dc: String,
}

/// Scans the segment on `interface`.
pub fn scan(interface: &str) -> Result<Vec<ScannedSubDevice>, CliError> {
    let fail = |source| CliError::EtherCat {
        interface: interface.to_string(),
        source,
    };
    // The PDU storage must outlive the MainDevice's socket task: one small leak per scan
    // (16 frames of 1.1 kB), which a command that scans once per process can afford.
    let storage: &'static PduStorage<MAX_FRAMES, MAX_PDU_DATA> =
        Box::leak(Box::new(PduStorage::new()));
    let (tx, rx, pdu_loop) = storage
        .try_split()
        .map_err(|()| fail(ethercrab::error::Error::Internal))?;
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(1)
        .enable_time()
        .build()
        .map_err(CliError::Runtime)?;
    let task = tx_rx_task(interface, tx, rx).map_err(|source| CliError::EtherCatSocket {
        interface: interface.to_string(),
        source,
    })?;
    runtime.block_on(async {
        let _io = tokio::spawn(task);
        let md = MainDevice::new(
            pdu_loop,
            Timeouts {
                pdu: PDU_TIMEOUT,
                ..Timeouts::default()
            },
            MainDeviceConfig {
                dc_static_sync_iterations: DC_ITERATIONS,
                ..MainDeviceConfig::default()
            },
        );
        match tokio::time::timeout(SCAN_TIMEOUT, list(&md)).await {
            Ok(result) => result.map_err(fail),
            Err(_) => Err(CliError::EtherCatTimeout {
                interface: interface.to_string(),
                within: SCAN_TIMEOUT,
            }),
        }
    })
}

async fn list(md: &MainDevice<'_>) -> Result<Vec<ScannedSubDevice>, ethercrab::error::Error> {
    let group = md
        .init_single_group::<MAX_SUBDEVICES, MAX_PDI>(ethercat_now)
        .await?;
    let group = group.into_pre_op_pdi(md).await?;
    let mut out = Vec::new();
    for (position, sd) in group.iter(md).enumerate() {
        let id = sd.identity();
        let io = sd.io_raw();
        out.push(ScannedSubDevice {
            position,
            address: sd.configured_address(),
            vendor: id.vendor_id,
            product: id.product_id,
            revision: id.revision,
            serial: id.serial,
            name: sd.name().to_string(),
            inputs: io.inputs().len(),
            outputs: io.outputs().len(),
            dc: format!("{:?}", sd.dc_support()),
        });
    }
    Ok(out)
}

/// Prints the scan as a table.
pub fn print(list: &[ScannedSubDevice], out: &mut impl Write) -> Result<(), CliError> {
    let mut text = format!(
        "{:>3}  {:<6}  {:<10}  {:<10}  {:<10}  {:>8}  {:<12}  {:>5}  {:>6}  {}\n",
        "pos", "addr", "vendor", "product", "revision", "serial", "name", "in", "out", "dc"
    );
    for s in list {
        text.push_str(&format!(
            "{:>3}  {:#06x}  {:#010x}  {:#010x}  {:#010x}  {:>8}  {:<12}  {:>5}  {:>6}  {}\n",
            s.position,
            s.address,
            s.vendor,
            s.product,
            s.revision,
            s.serial,
            s.name,
            s.inputs,
            s.outputs,
            s.dc
        ));
    }
    text.push_str(&format!("{} SubDevice(s)\n", list.len()));
    out.write_all(text.as_bytes()).map_err(CliError::Runtime)
}
