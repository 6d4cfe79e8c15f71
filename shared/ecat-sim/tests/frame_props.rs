//! Frames from the network are untrusted: whatever arrives, the segment never panics, and a
//! frame it answers keeps its length, every datagram's command, index and length field, and
//! the bytes outside the datagrams; only ADP, data, working counters and the source MAC's
//! locally administered bit may change. Property tests with a fixed seed.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use tandem_ecat_sim::{DeviceKind, DeviceOptions, Segment};

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: 2000,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(0x0ECA_7001),
        ..ProptestConfig::default()
    }
}

fn segment() -> Segment {
    Segment::new(
        &[
            DeviceKind::Cia402Drive,
            DeviceKind::DigitalIo,
            DeviceKind::Cia402Drive,
        ],
        DeviceOptions::default(),
    )
    .unwrap()
}

/// (command, index, ADP, ADO, data)
type Datagram = (u8, u8, u16, u16, Vec<u8>);

fn datagram() -> impl Strategy<Value = Datagram> {
    (
        0u8..16,
        any::<u8>(),
        prop_oneof![
            Just(0u16),
            Just(0xFFFF),
            Just(0x1000),
            Just(0x1001),
            any::<u16>()
        ],
        prop_oneof![
            0u16..0x0200,
            0x0500u16..0x0A00,
            0x0F00u16..0x1200,
            any::<u16>()
        ],
        prop::collection::vec(any::<u8>(), 0..200),
    )
}

fn frame(datagrams: &[Datagram]) -> (Vec<u8>, Vec<usize>) {
    let mut body = Vec::new();
    let mut starts = Vec::new();
    for (k, (c, i, adp, ado, data)) in datagrams.iter().enumerate() {
        starts.push(body.len());
        let more = if k + 1 < datagrams.len() { 0x8000 } else { 0 };
        body.extend_from_slice(&[*c, *i]);
        body.extend_from_slice(&adp.to_le_bytes());
        body.extend_from_slice(&ado.to_le_bytes());
        body.extend_from_slice(&(data.len() as u16 | more).to_le_bytes());
        body.extend_from_slice(&[0, 0]);
        body.extend_from_slice(data);
        body.extend_from_slice(&[0, 0]);
    }
    let mut f = vec![0xFF; 6];
    f.extend_from_slice(&[0x10; 6]);
    f.extend_from_slice(&[0x88, 0xA4]);
    f.extend_from_slice(&(0x1000 | body.len() as u16).to_le_bytes());
    f.extend_from_slice(&body);
    (f, starts)
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn well_formed_frames_keep_their_structure(datagrams in prop::collection::vec(datagram(), 1..6)) {
        let mut s = segment();
        let (mut f, starts) = frame(&datagrams);
        let before = f.clone();
        s.process_frame(&mut f, 1_000_000).unwrap();
        prop_assert_eq!(f.len(), before.len());
        prop_assert_eq!(f[6], before[6] | 0x02);
        prop_assert_eq!(&f[0..6], &before[0..6]);
        prop_assert_eq!(&f[7..16], &before[7..16]);
        for at in starts {
            let h = 16 + at;
            // Command, index, ADO, length/flags, IRQ unchanged.
            prop_assert_eq!(&f[h..h + 2], &before[h..h + 2]);
            prop_assert_eq!(&f[h + 4..h + 10], &before[h + 4..h + 10]);
        }
    }

    #[test]
    fn a_refused_frame_changes_nothing(
        datagrams in prop::collection::vec(datagram(), 1..4),
        cut in 0usize..40,
        garbage in prop::collection::vec(any::<u8>(), 0..300),
        header in any::<u16>(),
    ) {
        // A frame whose last datagram claims more data than the frame holds (the EtherCAT
        // header's length still right): refused whole, although the datagrams before it are
        // well formed.
        let (mut overrun, starts) = frame(&datagrams);
        let last = 16 + starts[starts.len() - 1] + 6;
        let len = u16::from_le_bytes([overrun[last], overrun[last + 1]]);
        let more = (len & 0x07FF) + 2 + cut as u16 + 1;
        overrun[last..last + 2].copy_from_slice(&((len & 0xF800) | more.min(0x07FF)).to_le_bytes());
        let mut random = vec![0xFF; 6];
        random.extend_from_slice(&[0x10; 6]);
        random.extend_from_slice(&[0x88, 0xA4]);
        random.extend_from_slice(&header.to_le_bytes());
        random.extend_from_slice(&garbage);
        let mut s = segment();
        let mut f = overrun.clone();
        prop_assert!(s.process_frame(&mut f, 0).is_err());
        for mut f in [overrun, random, garbage.clone()] {
            let mut s = segment();
            let memory: Vec<Vec<u8>> = s.escs().iter().map(|e| e.memory().to_vec()).collect();
            let before = f.clone();
            if s.process_frame(&mut f, 0).is_err() {
                prop_assert_eq!(&f, &before);
                for (esc, m) in s.escs().iter().zip(&memory) {
                    prop_assert!(esc.memory() == m.as_slice());
                }
            } else {
                prop_assert_eq!(f.len(), before.len());
            }
        }
    }
}
