//! A minimal HTTP/1.1 client for the crowd's visitors: one keep-alive
//! connection per visitor (as a browser tab's fetches to one origin mostly
//! are), bodies read through one buffer per visitor that is reused for every
//! response and kept only when asked. reqwest allocated a fresh chunk for
//! every read and spread each visitor's work over more wake-ups; on the
//! shared 2-core machine the harness's CPU is taken from the server's.

use std::time::{Duration, Instant};
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::TcpStream;

/// Read buffer per visitor.
const BUF: usize = 32 * 1024;
const MAX_HEAD: usize = 16 * 1024;

pub struct Conn {
    addr: String,
    /// `Host`, `User-Agent`, `Accept` and `Authorization`, ready to send.
    headers: String,
    stream: Option<TcpStream>,
    buf: Vec<u8>,
    /// Bytes of `buf` read past the last response (none in practice).
    start: usize,
    end: usize,
    connect_timeout: Duration,
}

/// One answer: the head, and the body when kept.
pub struct Answer {
    pub status: u16,
    pub retry_after_s: Option<f64>,
    /// From the request's start to the parsed head.
    pub head: Duration,
    pub bytes: u64,
    pub body: Option<Vec<u8>>,
}

/// What a response head says about the body and the connection.
struct Head {
    status: u16,
    retry_after_s: Option<f64>,
    length: Option<u64>,
    chunked: bool,
    close: bool,
}

impl Head {
    fn of(response: &httparse::Response) -> Head {
        let mut head = Head {
            status: response.code.unwrap_or(0),
            retry_after_s: None,
            length: None,
            chunked: false,
            close: false,
        };
        for h in response.headers.iter() {
            let v = std::str::from_utf8(h.value).unwrap_or("").trim();
            if h.name.eq_ignore_ascii_case("content-length") {
                head.length = v.parse::<u64>().ok();
            } else if h.name.eq_ignore_ascii_case("transfer-encoding") {
                head.chunked = v.eq_ignore_ascii_case("chunked");
            } else if h.name.eq_ignore_ascii_case("connection") {
                head.close = v.eq_ignore_ascii_case("close");
            } else if h.name.eq_ignore_ascii_case("retry-after") {
                head.retry_after_s = v.parse::<f64>().ok();
            }
        }
        head
    }
}

impl Conn {
    /// `base_url` is `http://host:port`.
    pub fn new(
        base_url: &str,
        user_agent: &str,
        authorization: Option<&str>,
        connect_timeout: Duration,
    ) -> Conn {
        let addr = base_url
            .trim_start_matches("http://")
            .trim_end_matches('/')
            .to_owned();
        let mut headers = format!("Host: {addr}\r\nUser-Agent: {user_agent}\r\nAccept: */*\r\n");
        if let Some(a) = authorization {
            headers.push_str(&format!("Authorization: {a}\r\n"));
        }
        Conn {
            addr,
            headers,
            stream: None,
            buf: Vec::new(),
            start: 0,
            end: 0,
            connect_timeout,
        }
    }

    /// GET `path`; the body is kept when `keep` or when the status is not 2xx.
    pub async fn get(&mut self, path: &str, keep: bool) -> Result<Answer, String> {
        let started = Instant::now();
        let reused = self.stream.is_some();
        match self.exchange(path, keep, started).await {
            Ok(a) => Ok(a),
            // A kept-alive connection the server closed while idle: once more
            // on a fresh one, as browsers and reqwest do.
            Err(Error::Stale) if reused => {
                self.stream = None;
                self.exchange(path, keep, started)
                    .await
                    .map_err(|e| e.to_string())
            }
            Err(e) => {
                self.stream = None;
                Err(e.to_string())
            }
        }
    }

    async fn exchange(
        &mut self,
        path: &str,
        keep: bool,
        started: Instant,
    ) -> Result<Answer, Error> {
        self.send(path).await?;
        let h = self.head().await?;
        let head = started.elapsed();
        let keep = keep || !(200..300).contains(&h.status);
        let mut body = keep.then(Vec::new);
        let bytes = self.read_body(&h, &mut body).await?;
        if h.close {
            self.stream = None;
        }
        Ok(Answer {
            status: h.status,
            retry_after_s: h.retry_after_s,
            head,
            bytes,
            body,
        })
    }

    /// Writes the request, on a new connection when there is none.
    async fn send(&mut self, path: &str) -> Result<(), Error> {
        if self.buf.is_empty() {
            self.buf = vec![0; BUF];
        }
        if self.stream.is_none() {
            let s = tokio::time::timeout(self.connect_timeout, TcpStream::connect(&self.addr))
                .await
                .map_err(|_| Error::Other("connect timed out".into()))?
                .map_err(|e| Error::Other(format!("connect: {e}")))?;
            let _ = s.set_nodelay(true);
            self.stream = Some(s);
            self.start = 0;
            self.end = 0;
        }
        let request = format!("GET {path} HTTP/1.1\r\n{}\r\n", self.headers);
        let stream = self.stream.as_mut().ok_or(Error::Stale)?;
        if stream.write_all(request.as_bytes()).await.is_err() {
            return Err(Error::Stale);
        }
        Ok(())
    }

    /// Reads the response head, leaving the buffer at the body.
    async fn head(&mut self) -> Result<Head, Error> {
        loop {
            let mut names = [httparse::EMPTY_HEADER; 32];
            let mut response = httparse::Response::new(&mut names);
            match response.parse(&self.buf[self.start..self.end]) {
                Ok(httparse::Status::Complete(n)) => {
                    let head = Head::of(&response);
                    self.start += n;
                    return Ok(head);
                }
                Ok(httparse::Status::Partial) => {
                    if self.end - self.start >= MAX_HEAD {
                        return Err(Error::Other("response head too large".into()));
                    }
                    let got = match self.fill().await {
                        // Reset before any answer: the server closed the
                        // idle connection as the request went out.
                        Err(_) if self.end == self.start => return Err(Error::Stale),
                        r => r?,
                    };
                    if got == 0 {
                        // Nothing at all on a reused connection: closed while idle.
                        return Err(if self.end == self.start {
                            Error::Stale
                        } else {
                            Error::Other("connection closed in the head".into())
                        });
                    }
                }
                Err(e) => return Err(Error::Other(format!("bad response head: {e}"))),
            }
        }
    }

    /// Reads the body `h` announces into `body` (when kept); returns its length.
    async fn read_body(&mut self, h: &Head, body: &mut Option<Vec<u8>>) -> Result<u64, Error> {
        let mut bytes = 0u64;
        if h.chunked {
            loop {
                let size = self.chunk_size().await?;
                self.body(size, body, &mut bytes).await?;
                self.expect_crlf().await?;
                if size == 0 {
                    break;
                }
            }
        } else if let Some(n) = h.length {
            self.body(n, body, &mut bytes).await?;
        } else if h.status != 204 && h.status != 304 {
            // No length: the body runs to the end of the connection.
            loop {
                self.body_available(body, &mut bytes, usize::MAX);
                if self.fill().await? == 0 {
                    break;
                }
            }
            self.stream = None;
        }
        Ok(bytes)
    }

    /// Reads more into the buffer (compacting it first); 0 at end of stream.
    async fn fill(&mut self) -> Result<usize, Error> {
        if self.start == self.end {
            self.start = 0;
            self.end = 0;
        } else if self.end == self.buf.len() {
            self.buf.copy_within(self.start..self.end, 0);
            self.end -= self.start;
            self.start = 0;
        }
        let stream = self.stream.as_mut().ok_or(Error::Stale)?;
        let n = stream
            .read(&mut self.buf[self.end..])
            .await
            .map_err(|e| Error::Other(format!("read: {e}")))?;
        self.end += n;
        Ok(n)
    }

    /// Takes up to `max` buffered bytes as body.
    fn body_available(&mut self, body: &mut Option<Vec<u8>>, bytes: &mut u64, max: usize) -> usize {
        let n = (self.end - self.start).min(max);
        if let Some(b) = body {
            b.extend_from_slice(&self.buf[self.start..self.start + n]);
        }
        self.start += n;
        *bytes += n as u64;
        n
    }

    async fn body(
        &mut self,
        mut left: u64,
        body: &mut Option<Vec<u8>>,
        bytes: &mut u64,
    ) -> Result<(), Error> {
        while left > 0 {
            if self.start == self.end && self.fill().await? == 0 {
                return Err(Error::Other("body cut off".into()));
            }
            let max = usize::try_from(left).unwrap_or(usize::MAX);
            left -= self.body_available(body, bytes, max) as u64;
        }
        Ok(())
    }

    async fn line(&mut self) -> Result<String, Error> {
        loop {
            if let Some(i) = self.buf[self.start..self.end]
                .windows(2)
                .position(|w| w == b"\r\n")
            {
                let line = String::from_utf8_lossy(&self.buf[self.start..self.start + i]).into();
                self.start += i + 2;
                return Ok(line);
            }
            if self.end - self.start >= MAX_HEAD || self.fill().await? == 0 {
                return Err(Error::Other("bad chunked body".into()));
            }
        }
    }

    async fn chunk_size(&mut self) -> Result<u64, Error> {
        let line = self.line().await?;
        let hex = line.split(';').next().unwrap_or("").trim();
        u64::from_str_radix(hex, 16).map_err(|_| Error::Other(format!("bad chunk size {hex:?}")))
    }

    async fn expect_crlf(&mut self) -> Result<(), Error> {
        let line = self.line().await?;
        if line.is_empty() {
            Ok(())
        } else {
            Err(Error::Other("bad chunk end".into()))
        }
    }
}

enum Error {
    /// The connection was closed before the request got any answer.
    Stale,
    Other(String),
}

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Error::Stale => write!(f, "connection closed"),
            Error::Other(e) => write!(f, "{e}"),
        }
    }
}
