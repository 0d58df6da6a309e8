//! Server load, sampled into a [`Pressure`] that pushes level caps down.
//!
//! Three signals: requests in flight, an EWMA of handler latency, and an EWMA
//! of how late the sampler's own timer fires (time spent queued behind other
//! tasks on the runtime). Any signal above its high threshold raises pressure
//! one step per sample; pressure falls one step only after `cooldown_samples`
//! samples with every signal below its low threshold. The gap between the
//! thresholds and the slow fall are the hysteresis.

use super::cap::Pressure;
use serde::Serialize;
use std::sync::atomic::{AtomicI32, AtomicU64, Ordering};
use std::sync::{Arc, Mutex, Weak};
use std::time::{Duration, Instant};

/// Weight of the newest sample in the EWMAs: a step change shows within ~5 samples.
const EWMA_ALPHA: f64 = 0.3;

#[derive(Clone, Debug, PartialEq)]
pub struct LoadConfig {
    pub high_inflight: u64,
    pub low_inflight: u64,
    pub high_latency: Duration,
    pub low_latency: Duration,
    pub high_queue: Duration,
    pub low_queue: Duration,
    pub sample_every: Duration,
    /// Pressure steps between no load cap and the good-enough level.
    pub steps: u8,
    /// Calm samples needed before pressure falls one step.
    pub cooldown_samples: u32,
    /// Sent with load-capped answers.
    pub retry_after: Duration,
}

impl Default for LoadConfig {
    fn default() -> Self {
        LoadConfig {
            high_inflight: 384,
            low_inflight: 128,
            high_latency: Duration::from_millis(250),
            low_latency: Duration::from_millis(50),
            high_queue: Duration::from_millis(25),
            low_queue: Duration::from_millis(5),
            sample_every: Duration::from_millis(250),
            steps: 4,
            cooldown_samples: 8,
            retry_after: Duration::from_secs(10),
        }
    }
}

/// What the sampler saw last, for `/metrics` and the manifest.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct LoadSnapshot {
    pub inflight: u64,
    pub latency_ms: f64,
    pub queue_ms: f64,
    pub pressure: u8,
    pub forced: bool,
}

#[derive(Debug, Default)]
struct Smoothed {
    latency_us: f64,
    queue_us: f64,
    calm_samples: u32,
    pressure: u8,
}

#[derive(Debug)]
pub struct LoadMonitor {
    config: LoadConfig,
    inflight: AtomicU64,
    latency_sum_us: AtomicU64,
    latency_count: AtomicU64,
    /// Pressure in effect; written by the sampler or by [`Self::force_pressure`].
    pressure: AtomicI32,
    /// A forced pressure (tests, operators), or -1.
    forced: AtomicI32,
    smoothed: Mutex<Smoothed>,
}

impl LoadMonitor {
    pub fn new(config: LoadConfig) -> Arc<LoadMonitor> {
        Arc::new(LoadMonitor {
            config,
            inflight: AtomicU64::new(0),
            latency_sum_us: AtomicU64::new(0),
            latency_count: AtomicU64::new(0),
            pressure: AtomicI32::new(0),
            forced: AtomicI32::new(-1),
            smoothed: Mutex::new(Smoothed::default()),
        })
    }

    pub fn config(&self) -> &LoadConfig {
        &self.config
    }

    pub fn pressure(&self) -> Pressure {
        Pressure {
            level: self.pressure.load(Ordering::Relaxed) as u8,
            steps: self.config.steps.max(1),
        }
    }

    /// Pins the pressure (`Some`) or hands it back to the sampler (`None`).
    pub fn force_pressure(&self, level: Option<u8>) {
        let steps = self.config.steps.max(1);
        match level {
            Some(l) => {
                self.forced
                    .store(i32::from(l.min(steps)), Ordering::Relaxed);
                self.pressure
                    .store(i32::from(l.min(steps)), Ordering::Relaxed);
            }
            None => {
                self.forced.store(-1, Ordering::Relaxed);
                let p = self.smoothed.lock().map(|s| s.pressure).unwrap_or(0);
                self.pressure.store(i32::from(p), Ordering::Relaxed);
            }
        }
    }

    /// Counts a request in flight until the guard drops, then records its latency.
    pub fn begin(self: &Arc<Self>) -> InflightGuard {
        let inflight = self.inflight.fetch_add(1, Ordering::Relaxed) + 1;
        if inflight >= self.config.high_inflight {
            self.surge(inflight);
        }
        InflightGuard {
            monitor: Arc::clone(self),
            started: Instant::now(),
        }
    }

    pub fn inflight(&self) -> u64 {
        self.inflight.load(Ordering::Relaxed)
    }

    pub fn snapshot(&self) -> LoadSnapshot {
        let s = self
            .smoothed
            .lock()
            .map(|s| (s.latency_us, s.queue_us))
            .unwrap_or_default();
        LoadSnapshot {
            inflight: self.inflight(),
            latency_ms: s.0 / 1000.0,
            queue_ms: s.1 / 1000.0,
            pressure: self.pressure().level,
            forced: self.forced.load(Ordering::Relaxed) >= 0,
        }
    }

    /// Fast attack: a crowd arriving at once outruns a sampler that climbs one
    /// step per period, so past `high_inflight` the pressure jumps at once,
    /// one step per further `high_inflight / steps` requests. It falls back
    /// through the sampler's usual cooldown.
    fn surge(&self, inflight: u64) {
        let c = &self.config;
        let steps = c.steps.max(1);
        let per_step = (c.high_inflight / u64::from(steps)).max(1);
        let target = (1 + (inflight - c.high_inflight) / per_step).min(u64::from(steps)) as u8;
        // Past the threshold every request lands here: take the lock only to raise.
        if self.forced.load(Ordering::Relaxed) < 0
            && i32::from(target) <= self.pressure.load(Ordering::Relaxed)
        {
            return;
        }
        let Ok(mut s) = self.smoothed.lock() else {
            return;
        };
        if target > s.pressure {
            s.pressure = target;
            s.calm_samples = 0;
            if self.forced.load(Ordering::Relaxed) < 0 {
                self.pressure.store(i32::from(target), Ordering::Relaxed);
            }
        }
    }

    /// One step of the controller, given how late the sampler woke up.
    pub fn sample(&self, queue_delay: Duration) -> Pressure {
        let sum = self.latency_sum_us.swap(0, Ordering::Relaxed) as f64;
        let count = self.latency_count.swap(0, Ordering::Relaxed) as f64;
        let inflight = self.inflight();
        let c = &self.config;
        let Ok(mut s) = self.smoothed.lock() else {
            return self.pressure();
        };
        let latest_latency = if count > 0.0 { sum / count } else { 0.0 };
        s.latency_us += EWMA_ALPHA * (latest_latency - s.latency_us);
        s.queue_us += EWMA_ALPHA * (queue_delay.as_micros() as f64 - s.queue_us);
        let us = |d: Duration| d.as_micros() as f64;
        let high = inflight >= c.high_inflight
            || s.latency_us >= us(c.high_latency)
            || s.queue_us >= us(c.high_queue);
        let low = inflight <= c.low_inflight
            && s.latency_us <= us(c.low_latency)
            && s.queue_us <= us(c.low_queue);
        if high {
            s.calm_samples = 0;
            s.pressure = (s.pressure + 1).min(c.steps.max(1));
        } else if low {
            s.calm_samples += 1;
            if s.calm_samples >= c.cooldown_samples.max(1) {
                s.calm_samples = 0;
                s.pressure = s.pressure.saturating_sub(1);
            }
        } else {
            s.calm_samples = 0;
        }
        if self.forced.load(Ordering::Relaxed) < 0 {
            self.pressure
                .store(i32::from(s.pressure), Ordering::Relaxed);
        }
        self.pressure()
    }

    /// Samples every `sample_every` until the monitor is dropped.
    pub fn spawn_sampler(self: &Arc<Self>) -> tokio::task::JoinHandle<()> {
        let weak: Weak<LoadMonitor> = Arc::downgrade(self);
        let period = self.config.sample_every.max(Duration::from_millis(1));
        tokio::spawn(async move {
            loop {
                let deadline = tokio::time::Instant::now() + period;
                tokio::time::sleep_until(deadline).await;
                let late = tokio::time::Instant::now().saturating_duration_since(deadline);
                let Some(monitor) = weak.upgrade() else { break };
                monitor.sample(late);
            }
        })
    }
}

/// A request in flight; dropping it records the request's latency.
#[derive(Debug)]
pub struct InflightGuard {
    monitor: Arc<LoadMonitor>,
    started: Instant,
}

impl Drop for InflightGuard {
    fn drop(&mut self) {
        let m = &self.monitor;
        m.inflight.fetch_sub(1, Ordering::Relaxed);
        m.latency_sum_us
            .fetch_add(self.started.elapsed().as_micros() as u64, Ordering::Relaxed);
        m.latency_count.fetch_add(1, Ordering::Relaxed);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn monitor() -> Arc<LoadMonitor> {
        LoadMonitor::new(LoadConfig {
            high_inflight: 4,
            low_inflight: 1,
            cooldown_samples: 2,
            ..LoadConfig::default()
        })
    }

    #[test]
    fn pressure_rises_under_load_and_falls_slowly_after() {
        let m = monitor();
        let guards: Vec<_> = (0..5).map(|_| m.begin()).collect();
        // Fast attack: 4 in flight (the threshold) is step 1, the fifth step 2.
        assert_eq!(m.pressure().level, 2);
        let rising: Vec<u8> = (0..4).map(|_| m.sample(Duration::ZERO).level).collect();
        assert_eq!(rising, vec![3, 4, 4, 4]);
        drop(guards);
        let falling: Vec<u8> = (0..8).map(|_| m.sample(Duration::ZERO).level).collect();
        assert_eq!(falling, vec![4, 3, 3, 2, 2, 1, 1, 0]);
    }

    #[test]
    fn between_thresholds_pressure_holds() {
        let m = monitor();
        let guards: Vec<_> = (0..4).map(|_| m.begin()).collect();
        assert_eq!(m.pressure().level, 1, "fast attack at the threshold");
        m.sample(Duration::ZERO);
        drop(guards);
        let _two: Vec<_> = (0..2).map(|_| m.begin()).collect(); // between the thresholds 1 and 4
        let held: Vec<u8> = (0..5).map(|_| m.sample(Duration::ZERO).level).collect();
        assert_eq!(held, vec![2; 5]);
    }

    #[test]
    fn queue_delay_counts_as_load_and_forcing_overrides() {
        let m = monitor();
        for _ in 0..10 {
            m.sample(Duration::from_millis(100));
        }
        assert_eq!(m.pressure().level, 4);
        m.force_pressure(Some(1));
        m.sample(Duration::from_millis(100));
        assert_eq!(m.pressure().level, 1);
        m.force_pressure(None);
        assert_eq!(m.pressure().level, 4);
    }
}
