//! Fault helpers: clients that hang up mid-batch, and a TCP proxy that adds
//! latency in front of a database.

use crate::sim::metric;
use anyhow::{bail, Result};
use std::time::{Duration, Instant};
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::{TcpListener, TcpStream};

/// `n` clients request `path`, read `read_bytes` of the answer (0: nothing)
/// and hang up. Afterwards the server must have nothing in flight, answer an
/// ordinary request, and have stayed up. Returns a one-line report.
pub async fn disconnects(addr: &str, path: &str, n: usize, read_bytes: usize) -> Result<String> {
    let before = rss_and_inflight(addr).await?;
    let mut tasks = Vec::new();
    for _ in 0..n {
        let (addr, path) = (addr.to_owned(), path.to_owned());
        tasks.push(tokio::spawn(async move {
            let mut s = TcpStream::connect(&addr).await?;
            s.write_all(format!("GET {path} HTTP/1.1\r\nhost: v\r\n\r\n").as_bytes())
                .await?;
            let mut got = 0;
            let mut buf = vec![0u8; 4096];
            while got < read_bytes {
                match s.read(&mut buf).await? {
                    0 => break,
                    k => got += k,
                }
            }
            drop(s);
            anyhow::Ok(got)
        }));
    }
    let mut read = 0;
    for t in tasks {
        read += t.await??;
    }
    // Handlers whose clients left must finish and leave the in-flight count.
    let deadline = Instant::now() + Duration::from_secs(10);
    let after = loop {
        let now = rss_and_inflight(addr).await?;
        if now.1 == 0.0 || Instant::now() > deadline {
            break now;
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    };
    if after.1 != 0.0 {
        bail!(
            "{} requests still in flight 10 s after the clients left",
            after.1
        );
    }
    let client = reqwest::Client::new();
    let status = client
        .get(format!("http://{addr}{path}"))
        .send()
        .await?
        .status();
    if !status.is_success() {
        bail!("after the disconnects {path} answered {status}");
    }
    Ok(format!(
        "{n} clients hung up after {} bytes each (read {read} in all); in flight afterwards: 0; next request: {status}; payload cache {:.1} → {:.1} MB",
        read_bytes,
        before.0 / 1e6,
        after.0 / 1e6
    ))
}

async fn rss_and_inflight(addr: &str) -> Result<(f64, f64)> {
    let text = reqwest::get(format!("http://{addr}/metrics"))
        .await?
        .text()
        .await?;
    Ok((
        metric(&text, "vitrine_payload_cache_bytes").unwrap_or(0.0),
        metric(&text, "vitrine_inflight_requests").unwrap_or(-1.0),
    ))
}

/// Forwards `listen` → `to`; everything the upstream sends reaches the
/// client `delay` later (a delay line: latency, not lower bandwidth).
pub async fn proxy(listen: &str, to: &str, delay: Duration) -> Result<()> {
    let listener = TcpListener::bind(listen).await?;
    eprintln!("proxy {listen} -> {to}, +{delay:?} on every answer");
    loop {
        let (inbound, _) = listener.accept().await?;
        let to = to.to_owned();
        tokio::spawn(async move {
            let Ok(outbound) = TcpStream::connect(&to).await else {
                return;
            };
            let _ = inbound.set_nodelay(true);
            let _ = outbound.set_nodelay(true);
            let (mut cr, mut cw) = inbound.into_split();
            let (mut ur, mut uw) = outbound.into_split();
            let up = tokio::spawn(async move { tokio::io::copy(&mut cr, &mut uw).await });
            let (tx, mut rx) = tokio::sync::mpsc::unbounded_channel::<(Instant, Vec<u8>)>();
            let reader = tokio::spawn(async move {
                let mut buf = vec![0u8; 64 * 1024];
                while let Ok(n) = ur.read(&mut buf).await {
                    if n == 0
                        || tx
                            .send((Instant::now() + delay, buf[..n].to_vec()))
                            .is_err()
                    {
                        break;
                    }
                }
            });
            while let Some((due, bytes)) = rx.recv().await {
                tokio::time::sleep_until(due.into()).await;
                if cw.write_all(&bytes).await.is_err() {
                    break;
                }
            }
            reader.abort();
            up.abort();
        });
    }
}
