//! The per-sender command rate (docs/gateway.md, "Command rate"): a token bucket per sender,
//! so that one sender's flood gets the reply `busy` while every other sender's commands go
//! through. Time is an input (ns, any monotonic clock).

use std::collections::HashMap;

/// Senders remembered at most; beyond, the fullest buckets (idle senders) are forgotten.
pub const MAX_SENDERS: usize = 1024;

/// A token bucket: `burst` tokens, refilled at `rate` per second; a command takes one.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct TokenBucket {
    tokens: f64,
    last_ns: i64,
    rate: f64,
    burst: f64,
}

impl TokenBucket {
    /// A full bucket at `now_ns`.
    pub fn new(rate_hz: f64, burst: u32, now_ns: i64) -> Self {
        let burst = f64::from(burst.max(1));
        Self {
            tokens: burst,
            last_ns: now_ns,
            rate: rate_hz.max(0.0),
            burst,
        }
    }

    /// Takes a token at `now_ns`: `true` if there was one.
    pub fn take(&mut self, now_ns: i64) -> bool {
        let dt = now_ns.saturating_sub(self.last_ns).max(0) as f64 * 1e-9;
        self.last_ns = self.last_ns.max(now_ns);
        self.tokens = (self.tokens + dt * self.rate).min(self.burst);
        if self.tokens >= 1.0 {
            self.tokens -= 1.0;
            true
        } else {
            false
        }
    }

    /// Full (the sender was idle long enough to be forgotten).
    fn full_at(&self, now_ns: i64) -> bool {
        let dt = now_ns.saturating_sub(self.last_ns).max(0) as f64 * 1e-9;
        self.tokens + dt * self.rate >= self.burst
    }
}

/// The buckets of every sender.
#[derive(Clone, Debug)]
pub struct SenderRates {
    rate_hz: f64,
    burst: u32,
    buckets: HashMap<String, TokenBucket>,
}

impl SenderRates {
    /// `rate_hz` commands per second and sender, `burst` at once.
    pub fn new(rate_hz: f64, burst: u32) -> Self {
        Self {
            rate_hz,
            burst,
            buckets: HashMap::new(),
        }
    }

    /// Whether `sender` may send a command at `now_ns` (takes its token).
    pub fn admit(&mut self, sender: &str, now_ns: i64) -> bool {
        if let Some(b) = self.buckets.get_mut(sender) {
            return b.take(now_ns);
        }
        if self.buckets.len() >= MAX_SENDERS {
            self.buckets.retain(|_, b| !b.full_at(now_ns));
            if self.buckets.len() >= MAX_SENDERS {
                // Every remembered sender is active: a new one waits until one is idle.
                return false;
            }
        }
        let mut b = TokenBucket::new(self.rate_hz, self.burst, now_ns);
        let ok = b.take(now_ns);
        self.buckets.insert(sender.to_string(), b);
        ok
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
    use super::*;

    const S: i64 = 1_000_000_000;

    #[test]
    fn a_flood_gets_the_rate_and_the_burst_and_another_sender_all() {
        let mut r = SenderRates::new(20.0, 40);
        let (mut flood, mut other) = (0, 0);
        // 10,000 commands in 10 s from one sender, 50 from another.
        for i in 0..10_000i64 {
            let t = i * S / 1000;
            flood += usize::from(r.admit("flood", t));
            if i % 200 == 0 {
                other += usize::from(r.admit("operator", t));
            }
        }
        // 40 at once, then 20 per second over 9.999 s: 239.
        assert_eq!(flood, 40 + 199);
        assert_eq!(other, 50);
    }

    #[test]
    fn idle_senders_are_forgotten_when_the_table_is_full() {
        let mut r = SenderRates::new(1.0, 1);
        for i in 0..MAX_SENDERS {
            assert!(r.admit(&format!("s{i}"), 0));
        }
        // All active: a new one is refused.
        assert!(!r.admit("late", 0));
        // A second later every bucket is full again: forgotten, the new one admitted.
        assert!(r.admit("late", S));
    }
}
