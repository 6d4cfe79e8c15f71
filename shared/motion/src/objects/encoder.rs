//! The external encoder technology object (`TO_ExternalEncoder`, S7-1500T Motion Control V4.0
//! function manual, 3.6 'Technology object external encoder'): an actual position from outside (a
//! measuring wheel on the material, a line shaft), enabled with MC_Power, homed directly or by
//! absolute-encoder adjustment, and offered to followers as an actual-value leading value through
//! the extrapolation of [`crate::kinematics::extrapolation`].
//!
//! The raw position and velocity are an input of each cycle (the runtime's simulated source or,
//! later, a real encoder). Nothing here allocates after [`ExternalEncoder::new`].

use crate::catalog::alarm::status_bit;
use crate::catalog::error_id::ErrorId;
use crate::kinematics::extrapolation::{Extrapolated, ExtrapolationConfig, Extrapolator};
use crate::kinematics::modulo::Modulo;
use crate::objects::axis::{Command, EncoderType};
use crate::objects::job::{EventQueue, Instruction, JobEvent, JobEventKind, JobId};
use crate::objects::leading::LeadingValue;

/// Configuration of an external encoder.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct EncoderConfig {
    /// Cycle (s, > 0).
    pub cycle: f64,
    /// Modulo settings.
    pub modulo: Option<Modulo>,
    /// Incremental (homed by MC_Home 0/1) or absolute (homed; adjusted by 6/7).
    pub encoder: EncoderType,
    /// How the actual value is prepared for followers.
    pub extrapolation: ExtrapolationConfig,
}

/// What an external encoder shows after a cycle.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct EncoderStatus {
    /// Cycle time (ns).
    pub time_ns: i64,
    /// `StatusWord` (bit 0 Enable, bit 5 HomingDone).
    pub status_word: u32,
    /// Actual position (modulo-reduced).
    pub position: f64,
    /// Actual position, continuous.
    pub position_unwrapped: f64,
    /// Actual velocity.
    pub velocity: f64,
    /// `StatusExtrapolation`.
    pub extrapolated: Extrapolated,
}

impl EncoderStatus {
    /// Tests a status bit.
    pub fn has(&self, bit: u32) -> bool {
        self.status_word & bit != 0
    }
}

/// An external encoder.
#[derive(Clone, Debug)]
pub struct ExternalEncoder {
    cfg: EncoderConfig,
    enabled: bool,
    power_job: JobId,
    homed: bool,
    offset: f64,
    pos: f64,
    vel: f64,
    extrapolator: Extrapolator,
    events: EventQueue,
    next_id: JobId,
    now: i64,
    status: EncoderStatus,
}

impl ExternalEncoder {
    /// A disabled encoder. The cycle must be positive and finite.
    pub fn new(cfg: EncoderConfig) -> Result<Self, ErrorId> {
        if !(cfg.cycle.is_finite() && cfg.cycle > 0.0) {
            return Err(ErrorId::IllegalObject);
        }
        Ok(Self {
            extrapolator: Extrapolator::new(cfg.extrapolation, cfg.cycle),
            homed: cfg.encoder == EncoderType::Absolute,
            cfg,
            enabled: false,
            power_job: 0,
            offset: 0.0,
            pos: 0.0,
            vel: 0.0,
            events: EventQueue::default(),
            next_id: 1,
            now: 0,
            status: EncoderStatus::default(),
        })
    }

    /// The configuration.
    pub fn config(&self) -> &EncoderConfig {
        &self.cfg
    }

    /// The status after the last cycle.
    pub fn status(&self) -> &EncoderStatus {
        &self.status
    }

    /// Takes the oldest job event.
    pub fn pop_event(&mut self) -> Option<JobEvent> {
        self.events.pop()
    }

    /// The leading value for followers (actual-value coupling), when enabled.
    pub fn leading_value(&self) -> Option<LeadingValue> {
        self.enabled.then(|| {
            let e = self.extrapolator.last();
            LeadingValue {
                p: e.position,
                v: e.velocity,
                a: e.acceleration,
                modulo: self.cfg.modulo,
            }
        })
    }

    fn new_id(&mut self) -> JobId {
        let id = self.next_id;
        self.next_id = self.next_id.wrapping_add(1).max(1);
        id
    }

    fn emit(&mut self, job: JobId, instruction: Instruction, kind: JobEventKind) {
        self.events.push(JobEvent {
            job,
            instruction,
            kind,
            time_ns: self.now,
        });
    }

    /// MC_Power, MC_Reset and MC_Home (modes 0, 1, 6, 7) apply to an external encoder; every
    /// other instruction is refused with 16#8002.
    pub fn command(&mut self, cmd: &Command) -> Result<JobId, ErrorId> {
        match *cmd {
            Command::Power { enable, .. } => {
                if enable && !self.enabled {
                    self.power_job = self.new_id();
                    self.enabled = true;
                    self.extrapolator.reset(self.pos, self.vel);
                    self.emit(self.power_job, Instruction::Power, JobEventKind::Busy);
                    self.emit(
                        self.power_job,
                        Instruction::Power,
                        JobEventKind::Status(true),
                    );
                } else if !enable && self.enabled {
                    self.enabled = false;
                    self.emit(
                        self.power_job,
                        Instruction::Power,
                        JobEventKind::Status(false),
                    );
                }
                Ok(self.power_job)
            }
            Command::Reset { restart } => {
                if restart && self.enabled {
                    return Err(ErrorId::RestartWhileEnabled);
                }
                let id = self.new_id();
                if restart {
                    self.homed = self.cfg.encoder == EncoderType::Absolute;
                }
                self.emit(id, Instruction::Reset, JobEventKind::Done);
                Ok(id)
            }
            Command::Home { mode, position } => {
                if !position.is_finite() {
                    return Err(ErrorId::IllegalPosition);
                }
                let incremental = self.cfg.encoder == EncoderType::Incremental;
                let reduce = |p: f64| self.cfg.modulo.map(|m| m.wrap(p)).unwrap_or(p);
                let target = match mode {
                    0 | 7 => reduce(position),
                    1 | 6 => reduce(self.pos + position),
                    // Passive homing needs homing marks, which the simulated sources do not have.
                    2 | 8 | 10 => return Err(ErrorId::IllegalMode),
                    _ => return Err(ErrorId::IllegalMode),
                };
                if incremental && matches!(mode, 6 | 7) {
                    return Err(ErrorId::IllegalHomingModeIncremental);
                }
                let delta = target - self.pos;
                self.offset += delta;
                self.pos += delta;
                self.extrapolator.reset(self.pos, self.vel);
                self.homed = true;
                let id = self.new_id();
                self.emit(id, Instruction::Home, JobEventKind::Done);
                self.refresh();
                Ok(id)
            }
            _ => Err(ErrorId::IllegalObject),
        }
    }

    /// One cycle with the raw position and velocity of the source.
    pub fn step(&mut self, now_ns: i64, raw_p: f64, raw_v: f64) {
        self.now = now_ns;
        self.pos = raw_p + self.offset;
        self.vel = raw_v;
        if self.enabled {
            self.extrapolator.step(self.pos, self.vel);
        }
        self.refresh();
    }

    fn refresh(&mut self) {
        let mut sw = 0;
        if self.enabled {
            sw |= status_bit::ENABLE;
        }
        if self.homed {
            sw |= status_bit::HOMING_DONE;
        }
        self.status = EncoderStatus {
            time_ns: self.now,
            status_word: sw,
            position: self
                .cfg
                .modulo
                .map(|m| m.wrap(self.pos))
                .unwrap_or(self.pos),
            position_unwrapped: self.pos,
            velocity: self.vel,
            extrapolated: self.extrapolator.last(),
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cfg() -> EncoderConfig {
        EncoderConfig {
            cycle: 0.001,
            modulo: Some(Modulo {
                start: 0.0,
                length: 360.0,
            }),
            encoder: EncoderType::Incremental,
            extrapolation: ExtrapolationConfig {
                system_defined: false,
                ..ExtrapolationConfig::default()
            },
        }
    }

    #[test]
    fn power_home_and_leading_value() {
        let mut e = ExternalEncoder::new(cfg()).unwrap();
        e.step(0, 100.0, 10.0);
        assert_eq!(e.leading_value(), None, "no leading value while disabled");
        e.command(&Command::Power {
            enable: true,
            start_mode: crate::objects::axis::StartMode::PositionControlled,
            stop_mode: crate::objects::axis::StopMode::Emergency,
        })
        .unwrap();
        e.step(1_000_000, 100.01, 10.0);
        let lv = e.leading_value().unwrap();
        assert!((lv.p - 100.01).abs() < 1e-12);
        assert!(!e.status().has(status_bit::HOMING_DONE));
        e.command(&Command::Home {
            mode: 0,
            position: 370.0,
        })
        .unwrap();
        e.step(2_000_000, 100.02, 10.0);
        assert!((e.status().position - 10.01).abs() < 1e-9);
        assert!(e.status().has(status_bit::HOMING_DONE));
        assert_eq!(e.command(&Command::GearOut), Err(ErrorId::IllegalObject));
        assert_eq!(
            e.command(&Command::Home {
                mode: 7,
                position: 0.0
            }),
            Err(ErrorId::IllegalHomingModeIncremental)
        );
    }
}
