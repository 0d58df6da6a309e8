//! Admission of *new* visitors during a surge.
//!
//! A visit starts with the model's manifest; the base mesh and the batches
//! that follow are what costs. When more visitors arrive at once than the
//! service can start together, the excess is told to come back later (503
//! `busy` with `Retry-After`) instead of all of them queueing on the same
//! two cores, which slows every visitor already in progress. Requests of
//! visits in progress (payloads) are never refused here.
//!
//! A token bucket: `burst` new visitors at once, refilled at `rate` per
//! second; a manifest request takes a token or is refused. Refused clients
//! are spread over time like a waiting room without tickets: the service
//! counts refusals in a backlog that drains at `rate`, and a refused client
//! is told to retry when its place in that backlog comes up (`Retry-After`,
//! whole seconds, at least 1); clients add their own jitter (the harness
//! waits a uniform 0–1 s more). Nothing is refused while the bucket has
//! tokens, so arrivals spread over time never see it.
//!
//! Written here rather than taken from `governor` or tower's `RateLimit`:
//! those answer "not now" (or hold the request), while a refused visitor
//! needs its place in the queue to be told when to come back; the bucket
//! and the backlog are a dozen lines under one mutex.

use std::sync::Mutex;
use std::time::{Duration, Instant};

#[derive(Clone, Debug, PartialEq)]
pub struct AdmissionConfig {
    /// New visitors admitted per second once the burst is used up; 0 turns
    /// admission control off.
    pub rate: f64,
    /// New visitors admitted at once.
    pub burst: f64,
}

impl Default for AdmissionConfig {
    fn default() -> Self {
        AdmissionConfig {
            rate: 200.0,
            burst: 100.0,
        }
    }
}

#[derive(Debug)]
struct Bucket {
    tokens: f64,
    /// Refused visitors not yet due back (drains at `rate`).
    backlog: f64,
    at: Instant,
}

#[derive(Debug)]
pub struct Admission {
    config: AdmissionConfig,
    bucket: Mutex<Bucket>,
}

/// What a new visitor is told.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Admit {
    Yes,
    /// Come back after this long.
    Later(Duration),
}

impl Admission {
    pub fn new(config: AdmissionConfig) -> Admission {
        Admission {
            bucket: Mutex::new(Bucket {
                tokens: config.burst,
                backlog: 0.0,
                at: Instant::now(),
            }),
            config,
        }
    }

    pub fn enabled(&self) -> bool {
        self.config.rate > 0.0
    }

    pub fn admit(&self) -> Admit {
        self.admit_at(Instant::now())
    }

    fn admit_at(&self, now: Instant) -> Admit {
        let c = &self.config;
        if c.rate <= 0.0 {
            return Admit::Yes;
        }
        let Ok(mut b) = self.bucket.lock() else {
            return Admit::Yes;
        };
        let dt = now.saturating_duration_since(b.at).as_secs_f64();
        b.at = b.at.max(now);
        b.tokens = (b.tokens + dt * c.rate).min(c.burst.max(1.0));
        b.backlog = (b.backlog - dt * c.rate).max(0.0);
        if b.tokens >= 1.0 {
            b.tokens -= 1.0;
            return Admit::Yes;
        }
        b.backlog += 1.0;
        let secs = (b.backlog / c.rate).ceil().max(1.0);
        Admit::Later(Duration::from_secs_f64(secs.min(3600.0)))
    }

    /// Refused visitors still waiting for their turn (for `/metrics`).
    pub fn backlog(&self) -> f64 {
        let c = &self.config;
        self.bucket
            .lock()
            .map(|b| {
                let dt = Instant::now().saturating_duration_since(b.at).as_secs_f64();
                (b.backlog - dt * c.rate).max(0.0)
            })
            .unwrap_or(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_burst_is_admitted_then_spread_by_rate() {
        let a = Admission::new(AdmissionConfig {
            rate: 10.0,
            burst: 5.0,
        });
        let t = Instant::now();
        let answers: Vec<Admit> = (0..30).map(|_| a.admit_at(t)).collect();
        assert!(answers[..5].iter().all(|x| *x == Admit::Yes));
        let later: Vec<u64> = answers[5..]
            .iter()
            .map(|x| match x {
                Admit::Later(d) => d.as_secs(),
                Admit::Yes => 0,
            })
            .collect();
        // The k-th refused visitor comes back after ⌈k / rate⌉ s.
        assert_eq!(later[..10], [1; 10]);
        assert_eq!(later[10..20], [2; 10]);
        assert_eq!(later[20..], [3; 5]);
        // Half a second later, five tokens are back.
        let t = t + Duration::from_millis(500);
        assert_eq!(a.admit_at(t), Admit::Yes);
        let yes = (0..10).filter(|_| a.admit_at(t) == Admit::Yes).count();
        assert_eq!(yes, 4);
    }

    #[test]
    fn spread_arrivals_are_never_refused_and_zero_rate_is_off() {
        let a = Admission::new(AdmissionConfig {
            rate: 10.0,
            burst: 5.0,
        });
        let t = Instant::now();
        for i in 0..100 {
            assert_eq!(a.admit_at(t + Duration::from_millis(100 * i)), Admit::Yes);
        }
        let off = Admission::new(AdmissionConfig {
            rate: 0.0,
            burst: 0.0,
        });
        assert!(!off.enabled());
        assert!((0..1000).all(|_| off.admit_at(t) == Admit::Yes));
    }
}
