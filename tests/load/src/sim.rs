//! Simulated visitors that fetch like the viewer (`web/src/reconstruction.js`):
//! the manifest, then the textures it lists, the base mesh, then batches
//! 1, 2, … up to the manifest's cap. Batch k + 1 is requested as soon as
//! batch k has arrived, while k "decodes": the visitor waits the measured
//! decode time of that level (native, times a device factor) without using
//! CPU, as the decoding happens on the visitor's device, not on the server's.
//! A 403/429 `level_capped` answer stops the visitor at the level it has, as
//! in the viewer; when the cap is a load cap (it carries `Retry-After`, in
//! the manifest or the 429), the visitor reads the manifest again after that
//! wait and refines further once the cap has risen, for as long as it stays
//! (`CrowdConfig::stay`). Any other failure ends the visit.

use crate::close_up::{ClosePath, PartIndex};
use crate::http::Conn;
use anyhow::{Context, Result};
use reqwest::Client;
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicBool, AtomicU8, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Device {
    Desktop,
    Tablet,
}

impl Device {
    /// What the service's `guess_device` reads (server/src/service/visitor.rs).
    fn user_agent(self) -> &'static str {
        match self {
            Device::Desktop => {
                "Mozilla/5.0 (X11; Linux x86_64) AppleWebKit/537.36 Chrome/120.0 Safari/537.36 vitrine-load"
            }
            Device::Tablet => {
                "Mozilla/5.0 (iPad; CPU OS 17_0 like Mac OS X) AppleWebKit/605.1.15 Mobile/15E148 vitrine-load"
            }
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Audience {
    Public,
    Researcher,
}

/// How visitors arrive over the run.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Pattern {
    /// All at once (the thesis' JMeter runs).
    Burst,
    /// Arrival rate rising linearly from zero over this many seconds.
    Ramp(f64),
    /// Evenly spaced over this many seconds.
    Steady(f64),
}

impl std::str::FromStr for Pattern {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let secs = |v: &str| v.parse::<f64>().map_err(|e| format!("{s}: {e}"));
        match s.split_once(':') {
            None if s == "burst" => Ok(Pattern::Burst),
            Some(("ramp", v)) => Ok(Pattern::Ramp(secs(v)?)),
            Some(("steady", v)) => Ok(Pattern::Steady(secs(v)?)),
            _ => Err(format!(
                "pattern must be burst, ramp:SECS or steady:SECS, not {s:?}"
            )),
        }
    }
}

impl std::fmt::Display for Pattern {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Pattern::Burst => write!(f, "burst"),
            Pattern::Ramp(s) => write!(f, "ramp:{s}"),
            Pattern::Steady(s) => write!(f, "steady:{s}"),
        }
    }
}

impl Pattern {
    /// When visitor `i` of `n` arrives, from the start of the run.
    fn arrival(self, i: usize, n: usize) -> Duration {
        let x = i as f64 / n.max(1) as f64;
        Duration::from_secs_f64(match self {
            Pattern::Burst => 0.0,
            Pattern::Ramp(d) => d * x.sqrt(),
            Pattern::Steady(d) => d * x,
        })
    }
}

/// Native decode time of each level on this machine: `[0]` the base mesh,
/// `[k]` batch k.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DecodeProfile {
    pub model: String,
    pub decode_ms: Vec<f64>,
    pub vertices: Vec<u32>,
    pub bytes: Vec<u64>,
}

/// Fetches every level the token allows and decodes it `runs` times with
/// the codec, keeping the fastest time per level.
pub async fn measure_profile(
    base_url: &str,
    slug: &str,
    token: Option<&str>,
    runs: usize,
) -> Result<DecodeProfile> {
    let client = Client::new();
    let auth = |r: reqwest::RequestBuilder| match token {
        Some(t) => r.bearer_auth(t),
        None => r,
    };
    let manifest: serde_json::Value = auth(client.get(format!("{base_url}/api/models/{slug}")))
        .send()
        .await?
        .error_for_status()?
        .json()
        .await?;
    let cap = manifest["cap"]["level"]
        .as_u64()
        .context("manifest without cap")? as usize;
    let levels = manifest["levels"]
        .as_array()
        .context("manifest without levels")?;
    let mut payloads = Vec::new();
    let mut vertices = Vec::new();
    for level in levels.iter().take(cap + 1) {
        let url = level["url"].as_str().context("level without url")?;
        let bytes = auth(client.get(format!("{base_url}{url}")))
            .send()
            .await?
            .error_for_status()?
            .bytes()
            .await?;
        payloads.push(bytes.to_vec());
        vertices.push(level["vertices"].as_u64().unwrap_or(0) as u32);
    }
    let bytes = payloads.iter().map(|p| p.len() as u64).collect();
    let decode_ms = tokio::task::spawn_blocking(move || decode_times(&payloads, runs)).await??;
    Ok(DecodeProfile {
        model: slug.to_owned(),
        decode_ms,
        vertices,
        bytes,
    })
}

/// Each level's best decode time over `runs` decodes, in ms: the base mesh,
/// then each batch applied to the level below.
fn decode_times(payloads: &[Vec<u8>], runs: usize) -> Result<Vec<f64>> {
    let mut best = vec![f64::INFINITY; payloads.len()];
    for _ in 0..runs.max(1) {
        let t = Instant::now();
        let mut decoder =
            vitrine_codec::Decoder::new(&payloads[0], vitrine_codec::Limits::default())?;
        best[0] = best[0].min(t.elapsed().as_secs_f64() * 1e3);
        for (k, batch) in payloads.iter().enumerate().skip(1) {
            let t = Instant::now();
            decoder.apply_batch(batch)?;
            best[k] = best[k].min(t.elapsed().as_secs_f64() * 1e3);
        }
    }
    Ok(best)
}

/// What the crowd is.
#[derive(Clone, Debug)]
pub struct CrowdConfig {
    pub base_url: String,
    pub slug: String,
    pub token: Option<String>,
    pub visitors: usize,
    pub pattern: Pattern,
    pub tablet_share: f64,
    pub researcher_share: f64,
    /// Tablets decode this many times slower than the measured (native) time.
    pub tablet_factor: f64,
    pub request_timeout: Duration,
    /// How long a visitor held by a load cap stays, re-checking it.
    pub stay: Duration,
    /// Sends SIGTERM to this process this long after the start.
    pub sigterm: Option<(u32, Duration)>,
    /// Only the first visitor of each (device, audience) pair, one after another.
    pub sequential: bool,
    /// Visitors look closely at one region each and fetch only its parts
    /// once the charts begin (`close_up.rs`), as the viewer's
    /// `?refine=view` does; streams without parts are refined whole.
    pub close_up: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Kind {
    Manifest,
    Texture,
    Base,
    Batch,
    /// A charted stream's part index (close-ups).
    PartIndex,
    /// A head, part or split entry of a parted batch (close-ups).
    Part,
}

/// One HTTP request as the visitor saw it.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub struct Req {
    pub kind: Kind,
    /// From the start of the run.
    pub start_us: u64,
    /// To the last byte of the body.
    pub dur_us: u64,
    /// To the response head: how long the service took to answer, apart
    /// from moving the body through the (shared) CPU and loopback.
    #[serde(default)]
    pub head_us: u64,
    /// 0: no answer (connection refused, reset, timed out).
    pub status: u16,
    pub retry_after: bool,
    pub bytes: u64,
}

#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct VisitorResult {
    pub device: Option<Device>,
    pub audience: Option<Audience>,
    pub arrive_ms: f64,
    /// The cap in the manifest and why.
    pub manifest_cap: Option<u32>,
    pub manifest_reason: Option<String>,
    pub target: u32,
    /// `level_ms[k]`: when level k was on screen (decoded), from arrival.
    pub level_ms: Vec<f64>,
    /// A batch refused with 403/429: (level, status, reason).
    pub refused: Option<(u32, u16, Option<String>)>,
    pub failure: Option<String>,
    /// From arrival to the manifest request that was admitted (after 503
    /// `busy` answers and their `Retry-After`); `level_ms` counts from there.
    #[serde(default)]
    pub admission_wait_ms: f64,
    /// 503 answers before the manifest was admitted.
    #[serde(default)]
    pub refusals: u32,
    /// Which visitor of the crowd (for jitter).
    #[serde(skip)]
    pub who: usize,
    /// The level at which a load cap first held refinement.
    #[serde(default)]
    pub first_stop: Option<u32>,
    /// Manifest reads after a load cap, each after its `Retry-After`.
    #[serde(default)]
    pub rechecks: u32,
    /// A re-check found the cap risen and refinement went on.
    #[serde(default)]
    pub resumed: bool,
    /// Still held by a load cap when the visitor left (`--stay-s`).
    #[serde(default)]
    pub held_at_end: bool,
    /// The compression (model version) of the first manifest: every payload
    /// this visitor fetches must be of it.
    #[serde(default)]
    pub compression_id: Option<i64>,
    /// A re-read manifest named a newer version; the visitor stayed on its own.
    #[serde(default)]
    pub newer_version_seen: bool,
    /// A batch whose size is not that of the first manifest's level: a mix
    /// of two versions on one screen.
    #[serde(default)]
    pub mixed_versions: bool,
}

impl VisitorResult {
    pub fn reached(&self) -> Option<u32> {
        self.level_ms.len().checked_sub(1).map(|l| l as u32)
    }

    /// Where refinement first stopped (a load cap, or the visitor's target)
    /// and when: what the crowd did to this visitor, before any wait for a
    /// cap to lift.
    pub fn first_stop(&self) -> Option<(u32, f64)> {
        let level = self.first_stop.or(self.reached())?;
        Some((level, *self.level_ms.get(level as usize)?))
    }

    /// The cap this visitor ended at was set by load (manifest or 429).
    pub fn load_capped(&self) -> bool {
        self.manifest_reason.as_deref() == Some("load")
            || self
                .refused
                .as_ref()
                .is_some_and(|r| r.2.as_deref() == Some("load") || r.1 == 429)
    }

    pub fn complete(&self) -> bool {
        self.failure.is_none()
    }
}

pub struct CrowdOutcome {
    pub visitors: Vec<VisitorResult>,
    pub requests: Vec<Req>,
    pub wall: Duration,
    pub pressure_max: u8,
    /// When SIGTERM was sent, from the start.
    pub sigterm_at: Option<Duration>,
}

/// Visitor `i`'s device and audience: spread evenly through the crowd.
pub fn mix(i: usize, tablet_share: f64, researcher_share: f64) -> (Device, Audience) {
    // Low-discrepancy sequences, so that any prefix of the crowd has the mix.
    let frac = |a: f64| ((i + 1) as f64 * a).fract();
    let device = if frac(0.618_033_988_749_895) < tablet_share {
        Device::Tablet
    } else {
        Device::Desktop
    };
    let audience = if frac(0.754_877_666_246_693) < researcher_share {
        Audience::Researcher
    } else {
        Audience::Public
    };
    (device, audience)
}

struct Visit {
    config: Arc<CrowdConfig>,
    profile: Arc<DecodeProfile>,
    epoch: Instant,
}

struct Fetched {
    req: Req,
    body: Option<Vec<u8>>,
    error: Option<String>,
    retry_after_s: Option<f64>,
}

/// Most 503 answers one request is retried after.
const MAX_RETRIES: u32 = 60;

/// A deterministic uniform number in [0, 1) for (visitor, attempt).
fn jitter(visitor: usize, attempt: u32) -> f64 {
    let mut z = (visitor as u64) << 32 ^ u64::from(attempt) ^ 0x9e37_79b9_7f4a_7c15;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64
}

impl Visit {
    /// One request; the body is kept only when asked or when it is an error
    /// answer, else counted and dropped as it streams in.
    async fn fetch(&self, conn: &mut Conn, kind: Kind, path: &str, keep: bool) -> Fetched {
        let start = Instant::now();
        let mut req = Req {
            kind,
            start_us: start.duration_since(self.epoch).as_micros() as u64,
            dur_us: 0,
            head_us: 0,
            status: 0,
            retry_after: false,
            bytes: 0,
        };
        let answer = tokio::time::timeout(self.config.request_timeout, conn.get(path, keep)).await;
        req.dur_us = start.elapsed().as_micros() as u64;
        match answer {
            Ok(Ok(a)) => {
                req.head_us = a.head.as_micros() as u64;
                req.status = a.status;
                req.retry_after = a.retry_after_s.is_some();
                req.bytes = a.bytes;
                Fetched {
                    req,
                    body: a.body,
                    error: None,
                    retry_after_s: a.retry_after_s,
                }
            }
            Ok(Err(e)) => Fetched {
                req,
                body: None,
                error: Some(format!("{kind:?}: {e}")),
                retry_after_s: None,
            },
            Err(_) => Fetched {
                req,
                body: None,
                error: Some(format!("{kind:?}: timed out")),
                retry_after_s: None,
            },
        }
    }

    /// [`Self::fetch`], again after `Retry-After` (plus 0–1 s of jitter)
    /// while the answer is 503 with `Retry-After`, as the viewer does: the
    /// refused attempts go to `reqs`.
    async fn fetch_retrying(
        &self,
        conn: &mut Conn,
        kind: Kind,
        path: &str,
        keep: bool,
        who: usize,
        reqs: &mut Vec<Req>,
    ) -> Fetched {
        let mut attempt = 0;
        loop {
            let f = self.fetch(conn, kind, path, keep).await;
            match f.retry_after_s {
                Some(after) if f.req.status == 503 && attempt < MAX_RETRIES => {
                    reqs.push(f.req);
                    attempt += 1;
                    let wait = Duration::from_secs_f64(after.max(0.0) + jitter(who, attempt));
                    tokio::time::sleep(wait).await;
                }
                _ => return f,
            }
        }
    }

    async fn decode_wait(&self, level: usize, device: Device) {
        self.decode_wait_share(level, device, 1.0).await;
    }

    /// [`Self::decode_wait`] for `share` of the level's decoding.
    async fn decode_wait_share(&self, level: usize, device: Device, share: f64) {
        let ms = share * self.profile.decode_ms.get(level).copied().unwrap_or(0.0);
        let factor = match device {
            Device::Desktop => 1.0,
            Device::Tablet => self.config.tablet_factor,
        };
        tokio::time::sleep(Duration::from_secs_f64(ms * factor / 1e3)).await;
    }

    async fn run(
        self: Arc<Self>,
        who: usize,
        device: Device,
        audience: Audience,
        arrive: Duration,
    ) -> (VisitorResult, Vec<Req>) {
        tokio::time::sleep_until((self.epoch + arrive).into()).await;
        let mut page = self.open_page(who, device, audience);
        let path = format!("/api/models/{}", self.config.slug);
        let Some((manifest, t0)) = self.admitted(&mut page, &path).await else {
            return (page.result, page.reqs);
        };
        let last = manifest["last_level"].as_u64().unwrap_or(0) as u32;
        let cap = manifest["cap"]["level"].as_u64().unwrap_or(0) as u32;
        page.result.manifest_cap = Some(cap);
        page.result.manifest_reason = manifest["cap"]["reason"].as_str().map(str::to_owned);
        page.result.target = cap.min(last);
        page.result.compression_id = manifest["compression_id"].as_i64();
        page.sizes = level_sizes(&manifest);
        let urls = level_urls(&manifest);
        if urls.len() <= page.result.target as usize {
            page.result.failure = Some("manifest lists fewer levels than its cap".into());
            return (page.result, page.reqs);
        }
        if self.textures(&mut page, &manifest).await
            && self.base(&mut page, &urls[0], t0).await
            && self.close_up(&mut page, &manifest).await
        {
            self.refine_while_staying(&mut page, &path, &manifest, urls, t0)
                .await;
        }
        (page.result, page.reqs)
    }

    /// A visitor arrives: a fresh page with its own connection.
    fn open_page(&self, who: usize, device: Device, audience: Audience) -> Page {
        let arrived = Instant::now();
        let authorization = match (audience, &self.config.token) {
            (Audience::Researcher, Some(token)) => Some(format!("Bearer {token}")),
            _ => None,
        };
        Page {
            conn: Conn::new(
                &self.config.base_url,
                device.user_agent(),
                authorization.as_deref(),
                Duration::from_secs(10),
            ),
            result: VisitorResult {
                device: Some(device),
                audience: Some(audience),
                arrive_ms: arrived.duration_since(self.epoch).as_secs_f64() * 1e3,
                who,
                ..VisitorResult::default()
            },
            reqs: Vec::with_capacity(16),
            arrived,
            device,
            sizes: Vec::new(),
            close: None,
        }
    }

    /// Admission: the manifest, again after each 503 `busy` (Retry-After).
    /// Reconstruction is timed from the request that was admitted (returned
    /// with the manifest); the wait before it is kept apart.
    async fn admitted(&self, page: &mut Page, path: &str) -> Option<(serde_json::Value, Instant)> {
        let who = page.result.who;
        let m = self
            .fetch_retrying(
                &mut page.conn,
                Kind::Manifest,
                path,
                true,
                who,
                &mut page.reqs,
            )
            .await;
        page.reqs.push(m.req);
        let t0 = self.epoch + Duration::from_micros(m.req.start_us);
        page.result.admission_wait_ms = t0.duration_since(page.arrived).as_secs_f64() * 1e3;
        page.result.refusals = page.reqs.len() as u32 - 1;
        match (&m.body, m.req.status) {
            (Some(b), 200) => Some((serde_json::from_slice(b).unwrap_or_default(), t0)),
            _ => {
                page.fail(&m, "manifest");
                None
            }
        }
    }

    /// The manifest's textures, each fetched once; false when one fails.
    async fn textures(&self, page: &mut Page, manifest: &serde_json::Value) -> bool {
        let Some(textures) = manifest["textures"].as_array() else {
            return true;
        };
        let who = page.result.who;
        for t in textures {
            let url = t["url"].as_str().unwrap_or("");
            let f = self
                .fetch_retrying(
                    &mut page.conn,
                    Kind::Texture,
                    url,
                    false,
                    who,
                    &mut page.reqs,
                )
                .await;
            page.reqs.push(f.req);
            if f.req.status != 200 {
                page.fail(&f, "texture");
                return false;
            }
        }
        true
    }

    /// A close-up visitor's path through the parts (`close_up.rs`): the
    /// part index, fetched once; false when it fails. Nothing for a
    /// visitor who refines whole batches or a stream without parts.
    async fn close_up(&self, page: &mut Page, manifest: &serde_json::Value) -> bool {
        let link = manifest["nested_parts"]
            .as_str()
            .or(manifest["parts"].as_str());
        let (true, Some(link)) = (self.config.close_up, link) else {
            return true;
        };
        let who = page.result.who;
        let f = self
            .fetch_retrying(
                &mut page.conn,
                Kind::PartIndex,
                link,
                true,
                who,
                &mut page.reqs,
            )
            .await;
        page.reqs.push(f.req);
        if f.req.status != 200 {
            page.fail(&f, "part index");
            return false;
        }
        let path = f
            .body
            .as_deref()
            .ok_or_else(|| "an empty part index".to_owned())
            .and_then(|b| serde_json::from_slice::<PartIndex>(b).map_err(|e| e.to_string()))
            .and_then(|index| index.close_path(jitter(who, 4242)));
        match path {
            Ok(path) => {
                page.close = Some(path);
                true
            }
            Err(e) => {
                page.result.failure = Some(format!("part index: {e}"));
                false
            }
        }
    }

    /// The base mesh, fetched and decoded: level 0 on screen.
    async fn base(&self, page: &mut Page, url: &str, t0: Instant) -> bool {
        let who = page.result.who;
        let base = self
            .fetch_retrying(&mut page.conn, Kind::Base, url, false, who, &mut page.reqs)
            .await;
        page.reqs.push(base.req);
        if base.req.status != 200 {
            page.fail(&base, "base");
            return false;
        }
        self.decode_wait(0, page.device).await;
        page.result.level_ms.push(t0.elapsed().as_secs_f64() * 1e3);
        true
    }

    /// Refines to the cap; while a load cap holds (it comes with
    /// `Retry-After`), reads the manifest again after that wait and goes on
    /// when the cap has risen, as the viewer does, for as long as the
    /// visitor stays.
    async fn refine_while_staying(
        self: &Arc<Self>,
        page: &mut Page,
        path: &str,
        manifest: &serde_json::Value,
        mut urls: Vec<String>,
        t0: Instant,
    ) {
        let last = manifest["last_level"].as_u64().unwrap_or(0) as u32;
        let mut cap = ManifestCap::of(manifest, last);
        let mut from = 1;
        loop {
            let retry_after_s = match self.refine(page, &urls, from, t0).await {
                Stop::Failed => break,
                Stop::Refused { retry_after_s } => retry_after_s,
                Stop::AtCap if page.result.target < last => cap.retry_after_s,
                Stop::AtCap => None,
            };
            let Some(after) = retry_after_s else { break };
            let reached = page.result.reached().unwrap_or(0);
            page.result.first_stop.get_or_insert(reached);
            let Some(manifest) = self.recheck(page, path, after).await else {
                if page.result.held_at_end {
                    break;
                }
                // No manifest this time: wait as long again (the viewer does).
                from = reached as usize + 1;
                page.result.target = reached;
                cap.retry_after_s = Some(after);
                continue;
            };
            // Nothing more unless the cap has risen past what is on screen.
            from = reached as usize + 1;
            page.result.target = reached;
            // A newer version: this page goes on with the one it shows
            // (still served while it is not withdrawn), never mixes the two.
            let same = manifest["compression_id"].as_i64() == page.result.compression_id;
            page.result.newer_version_seen |= !same;
            let levels = if same {
                level_urls(&manifest)
            } else {
                urls.clone()
            };
            cap = ManifestCap::of(&manifest, last);
            if cap.level > reached && levels.len() > cap.level as usize {
                page.result.resumed = true;
                page.result.target = cap.level;
                urls = levels;
            }
        }
    }

    /// The manifest again after `after` seconds (plus jitter), unless the
    /// visitor leaves first (then `held_at_end`); `None` without a manifest.
    async fn recheck(&self, page: &mut Page, path: &str, after: f64) -> Option<serde_json::Value> {
        let who = page.result.who;
        let wait =
            Duration::from_secs_f64(after.max(0.0) + jitter(who, 1000 + page.result.rechecks));
        if page.arrived.elapsed() + wait > self.config.stay {
            page.result.held_at_end = true;
            return None;
        }
        tokio::time::sleep(wait).await;
        page.result.rechecks += 1;
        let m = self
            .fetch_retrying(
                &mut page.conn,
                Kind::Manifest,
                path,
                true,
                who,
                &mut page.reqs,
            )
            .await;
        page.reqs.push(m.req);
        m.body
            .as_deref()
            .filter(|_| m.req.status == 200)
            .and_then(|b| serde_json::from_slice::<serde_json::Value>(b).ok())
    }

    /// Batches `from..=target`, each decoded (waited for) before the next is
    /// shown, the next one fetched meanwhile.
    async fn refine(
        self: &Arc<Self>,
        page: &mut Page,
        urls: &[String],
        from: usize,
        t0: Instant,
    ) -> Stop {
        let who = page.result.who;
        let mut prefetch: Option<tokio::task::JoinHandle<Prefetch>> = None;
        for k in from..=page.result.target as usize {
            if let Some((step, bytes)) = page.close_step(k) {
                if let Some(stop) = self.fetch_close_step(page, k, &step).await {
                    return stop;
                }
                // Decoding one region's parts: the level's time in proportion.
                let whole = page.sizes.get(k).copied().unwrap_or(0).max(1);
                let share = (bytes as f64 / whole as f64).min(1.0);
                self.decode_wait_share(k, page.device, share).await;
                page.result.level_ms.push(t0.elapsed().as_secs_f64() * 1e3);
                continue;
            }
            let f = match prefetch.take() {
                Some(handle) => match handle.await {
                    Ok((f, c, retried)) => {
                        page.conn = c;
                        page.reqs.extend(retried);
                        f
                    }
                    Err(e) => {
                        page.result.failure = Some(format!("prefetch task: {e}"));
                        return Stop::Failed;
                    }
                },
                None => {
                    self.fetch_retrying(
                        &mut page.conn,
                        Kind::Batch,
                        &urls[k],
                        false,
                        who,
                        &mut page.reqs,
                    )
                    .await
                }
            };
            page.reqs.push(f.req);
            if let Some(stop) = page.refused_or_failed(&f, k) {
                return stop;
            }
            // The body is not kept (`keep` false): its length is in the record.
            let got = f.req.bytes;
            if f.req.status == 200 && page.sizes.get(k).is_some_and(|&want| want != got) {
                page.result.mixed_versions = true;
                page.result.failure = Some(format!(
                    "batch {k}: {got} bytes, but the version the page started with has {}",
                    page.sizes[k]
                ));
                return Stop::Failed;
            }
            if k < page.result.target as usize && page.close_step(k + 1).is_none() {
                prefetch = Some(self.prefetch(page, urls[k + 1].clone()));
            }
            self.decode_wait(k, page.device).await;
            page.result.level_ms.push(t0.elapsed().as_secs_f64() * 1e3);
        }
        Stop::AtCap
    }

    /// A close-up's URLs for level `k`, one after another: the stop, if
    /// one answer stops refinement.
    async fn fetch_close_step(&self, page: &mut Page, k: usize, urls: &[String]) -> Option<Stop> {
        let who = page.result.who;
        for url in urls {
            let f = self
                .fetch_retrying(&mut page.conn, Kind::Part, url, false, who, &mut page.reqs)
                .await;
            page.reqs.push(f.req);
            if let Some(stop) = page.refused_or_failed(&f, k) {
                return Some(stop);
            }
        }
        None
    }

    /// Fetches `url` on the page's connection in a task of its own, while
    /// the page decodes; the page gets its connection back with the answer.
    fn prefetch(
        self: &Arc<Self>,
        page: &mut Page,
        url: String,
    ) -> tokio::task::JoinHandle<Prefetch> {
        let visit = Arc::clone(self);
        let who = page.result.who;
        let mut c = std::mem::replace(
            &mut page.conn,
            Conn::new(&self.config.base_url, "", None, Duration::ZERO),
        );
        tokio::spawn(async move {
            let mut retried = Vec::new();
            let f = visit
                .fetch_retrying(&mut c, Kind::Batch, &url, false, who, &mut retried)
                .await;
            (f, c, retried)
        })
    }
}

/// A prefetched batch: the answer, the connection it came on, the refused
/// attempts before it.
type Prefetch = (Fetched, Conn, Vec<Req>);

/// One visitor's page: its connection, what it reached, every request sent.
struct Page {
    conn: Conn,
    result: VisitorResult,
    reqs: Vec<Req>,
    arrived: Instant,
    device: Device,
    /// Each level's payload size in the first manifest.
    sizes: Vec<u64>,
    /// A close-up visitor's path through the parts.
    close: Option<ClosePath>,
}

impl Page {
    /// What a close-up fetches for level `k` (URLs, bytes); `None` for a
    /// whole batch.
    fn close_step(&self, k: usize) -> Option<(Vec<String>, u64)> {
        let path = self.close.as_ref()?;
        path.steps.get(k.checked_sub(path.first_level)?).cloned()
    }

    fn fail(&mut self, f: &Fetched, what: &str) {
        self.result.failure = Some(
            f.error
                .clone()
                .unwrap_or_else(|| format!("{what}: HTTP {}", f.req.status)),
        );
    }

    /// Why refinement stops at batch `k`'s answer, if it does: a
    /// `level_capped` refusal (403/429), or any other answer but 200.
    fn refused_or_failed(&mut self, f: &Fetched, k: usize) -> Option<Stop> {
        if f.req.status == 403 || f.req.status == 429 {
            let body: serde_json::Value = f
                .body
                .as_deref()
                .and_then(|b| serde_json::from_slice(b).ok())
                .unwrap_or_default();
            if body["error"] == "level_capped" {
                let reason = body["reason"].as_str().map(str::to_owned);
                self.result
                    .refused
                    .get_or_insert((k as u32, f.req.status, reason));
                return Some(Stop::Refused {
                    retry_after_s: f.retry_after_s,
                });
            }
        }
        if f.req.status != 200 {
            self.fail(f, &format!("batch {k}"));
            return Some(Stop::Failed);
        }
        None
    }
}

/// Why [`Visit::refine`] stopped.
enum Stop {
    /// At the target: the manifest's cap, or the last level.
    AtCap,
    /// A batch answered 403/429 `level_capped`.
    Refused {
        retry_after_s: Option<f64>,
    },
    Failed,
}

/// The manifest's cap on refinement, and when to ask again (load caps only).
struct ManifestCap {
    level: u32,
    retry_after_s: Option<f64>,
}

impl ManifestCap {
    fn of(manifest: &serde_json::Value, last: u32) -> Self {
        let cap = &manifest["cap"];
        ManifestCap {
            level: (cap["level"].as_u64().unwrap_or(0) as u32).min(last),
            retry_after_s: cap["retry_after_s"].as_f64(),
        }
    }
}

/// Each level's payload size, base mesh first.
fn level_sizes(manifest: &serde_json::Value) -> Vec<u64> {
    manifest["levels"]
        .as_array()
        .map(|a| a.iter().map(|l| l["bytes"].as_u64().unwrap_or(0)).collect())
        .unwrap_or_default()
}

/// Each level's payload URL, base mesh first.
fn level_urls(manifest: &serde_json::Value) -> Vec<String> {
    manifest["levels"]
        .as_array()
        .map(|a| {
            a.iter()
                .map(|l| l["url"].as_str().unwrap_or("").to_owned())
                .collect()
        })
        .unwrap_or_default()
}

/// Runs a crowd to the end.
pub async fn run_crowd(config: CrowdConfig, profile: Arc<DecodeProfile>) -> Result<CrowdOutcome> {
    let config = Arc::new(config);
    let epoch = Instant::now();
    let visit = Arc::new(Visit {
        config: Arc::clone(&config),
        profile,
        epoch,
    });
    let done = Arc::new(AtomicBool::new(false));
    let pressure = Arc::new(AtomicU8::new(0));
    let sampler = tokio::spawn(sample_pressure(
        config.base_url.clone(),
        Arc::clone(&done),
        Arc::clone(&pressure),
    ));
    let sigterm = config
        .sigterm
        .map(|(pid, after)| tokio::spawn(sigterm_after(pid, after, epoch)));
    let (visitors, requests) = if config.sequential {
        lone_visitors(&config, &visit, epoch).await
    } else {
        crowd_of_visitors(&config, &visit).await?
    };
    let wall = epoch.elapsed();
    done.store(true, Ordering::Relaxed);
    let _ = sampler.await;
    let sigterm_at = match sigterm {
        Some(h) => Some(h.await?),
        None => None,
    };
    Ok(CrowdOutcome {
        visitors,
        requests,
        wall,
        pressure_max: pressure.load(Ordering::Relaxed),
        sigterm_at,
    })
}

/// Sends SIGTERM to `pid` `after` into the run; returns when, from `epoch`.
async fn sigterm_after(pid: u32, after: Duration, epoch: Instant) -> Duration {
    tokio::time::sleep(after).await;
    let at = epoch.elapsed();
    let _ = tokio::process::Command::new("kill")
        .args(["-TERM", &pid.to_string()])
        .status()
        .await;
    at
}

/// One visitor per (device, audience) pair present in the mix, alone, one
/// after another.
async fn lone_visitors(
    config: &CrowdConfig,
    visit: &Arc<Visit>,
    epoch: Instant,
) -> (Vec<VisitorResult>, Vec<Req>) {
    let (mut visitors, mut requests) = (Vec::new(), Vec::new());
    let mut seen = Vec::new();
    for i in 0..config.visitors {
        let pair = mix(i, config.tablet_share, config.researcher_share);
        if seen.contains(&pair) {
            continue;
        }
        seen.push(pair);
        let start = epoch.elapsed();
        let (r, q) = Arc::clone(visit).run(i, pair.0, pair.1, start).await;
        visitors.push(r);
        requests.extend(q);
    }
    (visitors, requests)
}

/// Every visitor at once, each arriving as the pattern says.
async fn crowd_of_visitors(
    config: &CrowdConfig,
    visit: &Arc<Visit>,
) -> Result<(Vec<VisitorResult>, Vec<Req>)> {
    let mut visitors = Vec::with_capacity(config.visitors);
    let mut requests = Vec::with_capacity(config.visitors * 16);
    let mut set = tokio::task::JoinSet::new();
    for i in 0..config.visitors {
        let (device, audience) = mix(i, config.tablet_share, config.researcher_share);
        let arrive = config.pattern.arrival(i, config.visitors);
        set.spawn(Arc::clone(visit).run(i, device, audience, arrive));
    }
    while let Some(joined) = set.join_next().await {
        let (r, q) = joined.context("visitor task")?;
        visitors.push(r);
        requests.extend(q);
    }
    Ok((visitors, requests))
}

/// Polls `/metrics` for the highest load pressure seen.
async fn sample_pressure(base_url: String, done: Arc<AtomicBool>, max: Arc<AtomicU8>) {
    let client = Client::new();
    while !done.load(Ordering::Relaxed) {
        if let Ok(r) = client
            .get(format!("{base_url}/metrics"))
            .timeout(Duration::from_secs(2))
            .send()
            .await
        {
            if let Ok(text) = r.text().await {
                if let Some(p) = metric(&text, "vitrine_load_pressure") {
                    max.fetch_max(p as u8, Ordering::Relaxed);
                }
            }
        }
        tokio::time::sleep(Duration::from_millis(250)).await;
    }
}

/// The value of an unlabelled metric in Prometheus text format.
pub fn metric(text: &str, name: &str) -> Option<f64> {
    text.lines()
        .filter(|l| !l.starts_with('#'))
        .find_map(|l| l.strip_prefix(name)?.strip_prefix(' ')?.trim().parse().ok())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patterns_parse_and_spread() {
        assert_eq!("burst".parse::<Pattern>(), Ok(Pattern::Burst));
        assert_eq!("ramp:10".parse::<Pattern>(), Ok(Pattern::Ramp(10.0)));
        assert!("steady".parse::<Pattern>().is_err());
        let p = Pattern::Steady(10.0);
        assert_eq!(p.arrival(5, 10), Duration::from_secs(5));
        assert!(Pattern::Ramp(10.0).arrival(1, 4) > Duration::from_secs(4));
    }

    #[test]
    fn mix_shares_hold_in_prefixes() {
        let tablets = (0..1000)
            .filter(|&i| mix(i, 0.3, 0.05).0 == Device::Tablet)
            .count();
        let researchers = (0..1000)
            .filter(|&i| mix(i, 0.3, 0.05).1 == Audience::Researcher)
            .count();
        assert!((280..=320).contains(&tablets), "{tablets}");
        assert!((40..=60).contains(&researchers), "{researchers}");
    }

    #[test]
    fn metric_lines() {
        let text = "# HELP x\nvitrine_load_pressure 3\nvitrine_load_pressure_other 9\n";
        assert_eq!(metric(text, "vitrine_load_pressure"), Some(3.0));
    }
}
