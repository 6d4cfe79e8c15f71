//! A virtual EtherCAT segment for commissioning without hardware and for tests.
//!
//! The core is pure: [`Segment`] takes an Ethernet frame, the time, and returns the frame as
//! the emulated SubDevices would have passed it on ([`Segment::process_frame`]); nothing here
//! does IO except [`net`], which binds the segment to a network interface through an
//! AF_PACKET raw socket (the `tandem-ecat-sim` binary).
//!
//! - [`esc`]: one EtherCAT SubDevice Controller: registers, AL state machine, SII, SyncManagers,
//!   FMMUs, mailbox, DC registers.
//! - [`segment`]: datagram processing (every command, auto-increment, working counters).
//! - [`sii`]: the generated SII EEPROM image.
//! - [`coe`]: the object dictionary and the SDO server.
//! - [`device`]: the devices: a CiA 402 servo drive (the project's simulated drive behind an
//!   object dictionary) and an 8-channel digital input/output terminal.

pub mod coe;
pub mod device;
pub mod esc;
pub mod net;
pub mod segment;
pub mod sii;

pub use device::{DeviceKind, DeviceOptions};
pub use esc::{AlState, AlStatusCode, Esc};
pub use segment::{FrameError, Segment};
pub use sii::Identity;
