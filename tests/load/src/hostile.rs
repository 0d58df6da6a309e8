//! Hostile HTTP against a running `vitrine serve`, over raw TCP where the
//! client library would tidy the request up: each case and the status it
//! must get.

use anyhow::{Context, Result};
use std::time::{Duration, Instant};
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::TcpStream;

pub struct Target {
    pub addr: String,
    pub slug: String,
    pub compression_id: i64,
    pub last_level: u32,
    pub token: Option<String>,
    /// Slow-client cases wait for the server's header timeout (10 s by default).
    pub slow: bool,
}

pub struct Case {
    pub name: String,
    pub expected: String,
    pub got: String,
    pub pass: bool,
}

/// Sends `request` as is; returns the status line's code (None: closed
/// without an answer) and the whole answer as text.
async fn raw(addr: &str, request: &[u8]) -> Result<(Option<u16>, String)> {
    let mut s = TcpStream::connect(addr).await?;
    let _ = s.write_all(request).await;
    let mut buf = Vec::new();
    let _ = tokio::time::timeout(Duration::from_secs(15), async {
        let mut chunk = [0u8; 8192];
        loop {
            match s.read(&mut chunk).await {
                Ok(0) | Err(_) => break,
                Ok(n) => {
                    buf.extend_from_slice(&chunk[..n]);
                    if buf.len() > 1 << 20 {
                        break;
                    }
                }
            }
        }
    })
    .await;
    let text = String::from_utf8_lossy(&buf).into_owned();
    let status = text
        .strip_prefix("HTTP/1.1 ")
        .and_then(|t| t.get(..3))
        .and_then(|c| c.parse().ok());
    Ok((status, text))
}

fn get(path: &str, extra: &str) -> Vec<u8> {
    format!("GET {path} HTTP/1.1\r\nhost: vitrine\r\n{extra}connection: close\r\n\r\n").into_bytes()
}

/// The cases so far.
#[derive(Default)]
struct Cases(Vec<Case>);

impl Cases {
    /// Passes when the answer's status is one of `expected` and the answer
    /// contains none of `forbid`.
    fn check(&mut self, name: &str, expected: &[u16], got: (Option<u16>, String), forbid: &[&str]) {
        let leaked = forbid.iter().find(|f| got.1.contains(**f));
        let pass = got.0.is_some_and(|s| expected.contains(&s)) && leaked.is_none();
        self.0.push(Case {
            name: name.into(),
            expected: expected
                .iter()
                .map(u16::to_string)
                .collect::<Vec<_>>()
                .join(" or "),
            got: match (got.0, leaked) {
                (_, Some(l)) => format!("LEAKED {l:?}"),
                (Some(s), None) => s.to_string(),
                (None, None) => "closed without an answer".into(),
            },
            pass,
        });
    }
}

pub async fn run(t: &Target) -> Result<Vec<Case>> {
    let mut cases = Cases::default();
    traversal(t, &mut cases).await?;
    oversized(t, &mut cases).await?;
    malformed(t, &mut cases).await?;
    tokens(t, &mut cases).await?;
    research_level(t, &mut cases).await?;
    // The database is intact after all of the above.
    cases.check(
        "model still listed afterwards",
        &[200],
        raw(&t.addr, &get(&format!("/api/models/{}", t.slug), "")).await?,
        &[],
    );
    if t.slow {
        slow_clients(t, &mut cases.0).await?;
    }
    Ok(cases.0)
}

/// Path traversal, raw and encoded, on the API, the viewer's pages and
/// files: no file of the machine may leak.
async fn traversal(t: &Target, cases: &mut Cases) -> Result<()> {
    let a = t.addr.as_str();
    let secret = ["root:x:0:0", "[workspace]", "PRIVATE KEY"];
    for path in [
        "/../../../../etc/passwd",
        "/%2e%2e/%2e%2e/%2e%2e/etc/passwd",
        "/assets/..%2f..%2f..%2f..%2fetc%2fpasswd",
        "/m/..%2f..%2f..%2fetc%2fpasswd",
        "/api/models/..%2f..%2fetc%2fpasswd",
        "/api/compressions/..%2f1/base",
        "/..%5c..%5c..%5cCargo.toml",
        "/%00/etc/passwd",
    ] {
        cases.check(
            &format!("path traversal GET {path}"),
            &[400, 404],
            raw(a, &get(path, "")).await?,
            &secret,
        );
    }
    Ok(())
}

/// Oversized and too many headers, oversized and streamed bodies, another
/// method, a garbage request line.
async fn oversized(t: &Target, cases: &mut Cases) -> Result<()> {
    let a = t.addr.as_str();
    let big = format!("x-big: {}\r\n", "a".repeat(64 * 1024));
    cases.check(
        "64 KiB header",
        &[431],
        raw(a, &get("/api/models", &big)).await?,
        &[],
    );
    let many: String = (0..100).map(|i| format!("x-h{i}: v\r\n")).collect();
    cases.check(
        "100 headers (limit 64)",
        &[431],
        raw(a, &get("/api/models", &many)).await?,
        &[],
    );
    cases.check(
        "declared 10 MB body",
        &[413],
        raw(a, &get("/api/models", "content-length: 10000000\r\n")).await?,
        &[],
    );
    let mut chunked = get("/api/models", "transfer-encoding: chunked\r\n");
    chunked.extend_from_slice(b"4\r\nabcd\r\n0\r\n\r\n");
    cases.check("chunked body", &[413], raw(a, &chunked).await?, &[]);
    cases.check(
        "POST to a read-only route",
        &[405],
        raw(
            a,
            b"POST /api/compressions/1/base HTTP/1.1\r\nhost: v\r\ncontent-length: 0\r\nconnection: close\r\n\r\n",
        )
        .await?,
        &[],
    );
    cases.check(
        "publishing without a curator token",
        &[401],
        raw(
            a,
            b"POST /api/models HTTP/1.1\r\nhost: v\r\ncontent-length: 0\r\nconnection: close\r\n\r\n",
        )
        .await?,
        &[],
    );
    cases.check(
        "garbage request line",
        &[400],
        raw(a, b"\x16\x03\x01 hello\r\n\r\n").await?,
        &[],
    );
    Ok(())
}

/// Invalid and SQL-injection-shaped ids, slugs and parameters.
async fn malformed(t: &Target, cases: &mut Cases) -> Result<()> {
    let a = t.addr.as_str();
    let id = t.compression_id;
    let last = t.last_level;
    for (path, expected) in [
        ("/api/compressions/abc/base".to_string(), &[400][..]),
        ("/api/compressions/-1/base".into(), &[400]),
        ("/api/compressions/0/base".into(), &[404]),
        ("/api/compressions/99999999999999999999/base".into(), &[400]),
        ("/api/compressions/1%20OR%201=1/base".into(), &[400]),
        (
            "/api/compressions/1;DROP%20TABLE%20model/base".into(),
            &[400],
        ),
        (format!("/api/compressions/{id}%27--/batches/1"), &[400]),
        (
            format!("/api/compressions/{id}/batches/1%20OR%201=1"),
            &[400],
        ),
        (format!("/api/compressions/{id}/batches/0"), &[404]),
        (
            format!("/api/compressions/{id}/batches/{}", last + 1),
            &[404],
        ),
        ("/api/models/x%27%20OR%20%271%27=%271".into(), &[400]),
        ("/api/models/igea%27;DROP%20TABLE%20model;--".into(), &[400]),
        (
            format!("/api/models/{}?device=desktop%27--", t.slug),
            &[400],
        ),
        ("/api/textures/1%20UNION%20SELECT%201".into(), &[400]),
    ] {
        cases.check(
            &format!("GET {path}"),
            expected,
            raw(a, &get(&path, "")).await?,
            &[],
        );
    }
    Ok(())
}

/// A token shaped like SQL injection, and another scheme than Bearer.
async fn tokens(t: &Target, cases: &mut Cases) -> Result<()> {
    let a = t.addr.as_str();
    cases.check(
        "token ' OR '1'='1",
        &[401],
        raw(
            a,
            &get(
                &format!("/api/models/{}", t.slug),
                "authorization: Bearer ' OR '1'='1\r\n",
            ),
        )
        .await?,
        &[],
    );
    cases.check(
        "Basic auth instead of Bearer",
        &[400],
        raw(
            a,
            &get(
                &format!("/api/models/{}", t.slug),
                "authorization: Basic dXNlcjpwdw==\r\n",
            ),
        )
        .await?,
        &[],
    );
    Ok(())
}

/// The full-resolution level without a token, with a made-up one, and with
/// the researcher's.
async fn research_level(t: &Target, cases: &mut Cases) -> Result<()> {
    let a = t.addr.as_str();
    let id = t.compression_id;
    let last = t.last_level;
    cases.check(
        &format!("full-resolution batch {last} without a token"),
        &[403],
        raw(
            a,
            &get(&format!("/api/compressions/{id}/batches/{last}"), ""),
        )
        .await?,
        &[],
    );
    cases.check(
        &format!("full-resolution batch {last} with a made-up token"),
        &[401],
        raw(
            a,
            &get(
                &format!("/api/compressions/{id}/batches/{last}"),
                "authorization: Bearer vtr_0000\r\n",
            ),
        )
        .await?,
        &[],
    );
    if let Some(token) = &t.token {
        cases.check(
            &format!("full-resolution batch {last} with the researcher token"),
            &[200],
            raw(
                a,
                &get(
                    &format!("/api/compressions/{id}/batches/{last}"),
                    &format!("authorization: Bearer {token}\r\n"),
                ),
            )
            .await?,
            &[],
        );
    }
    Ok(())
}

/// Slowloris: 200 connections that send headers one byte every second. The
/// server must drop them at its header timeout while serving others.
async fn slow_clients(t: &Target, cases: &mut Vec<Case>) -> Result<()> {
    let started = Instant::now();
    let mut slow = Vec::new();
    for _ in 0..200 {
        let addr = t.addr.clone();
        slow.push(tokio::spawn(async move {
            let Ok(mut s) = TcpStream::connect(&addr).await else {
                return None;
            };
            let t0 = Instant::now();
            let request = b"GET /api/models HTTP/1.1\r\nhost: vitrine\r\nx-slow: aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa";
            for b in request {
                if s.write_all(&[*b]).await.is_err() {
                    break;
                }
                // Any answer or a close ends the drip.
                let mut buf = [0u8; 64];
                match tokio::time::timeout(Duration::from_secs(1), s.read(&mut buf)).await {
                    Ok(Ok(0)) | Ok(Err(_)) => break,
                    Ok(Ok(_)) => break,
                    Err(_) => {}
                }
            }
            Some(t0.elapsed())
        }));
    }
    tokio::time::sleep(Duration::from_secs(2)).await;
    // Meanwhile an ordinary visitor is served promptly.
    let t0 = Instant::now();
    let (status, _) = raw(&t.addr, &get(&format!("/api/models/{}", t.slug), "")).await?;
    let served_in = t0.elapsed();
    cases.push(Case {
        name: "ordinary request during 200 slow clients".into(),
        expected: "200 within 1 s".into(),
        got: format!("{status:?} in {served_in:.2?}"),
        pass: status == Some(200) && served_in < Duration::from_secs(1),
    });
    let mut dropped = Vec::new();
    for h in slow {
        if let Some(d) = h.await.context("slow client task")? {
            dropped.push(d);
        }
    }
    dropped.sort();
    let worst = dropped.last().copied().unwrap_or_default();
    cases.push(Case {
        name: "200 slowloris clients (1 header byte/s)".into(),
        expected: "all dropped by the 10 s header timeout (< 15 s)".into(),
        got: format!(
            "{} dropped, last after {worst:.1?} (run {:.1?})",
            dropped.len(),
            started.elapsed()
        ),
        pass: dropped.len() == 200 && worst < Duration::from_secs(15),
    });
    Ok(())
}
