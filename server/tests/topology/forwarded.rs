//! Whose address a request is: the TCP peer, unless that peer is a trusted
//! proxy; then the nearest forwarded address that is not one.

use axum::http::{HeaderMap, HeaderValue};
use ipnet::IpNet;
use std::net::IpAddr;
use vitrine::service::client_address;

fn ip(s: &str) -> IpAddr {
    s.parse().unwrap()
}

fn nets(list: &[&str]) -> Vec<IpNet> {
    list.iter().map(|n| n.parse().unwrap()).collect()
}

fn headers(pairs: &[(&'static str, &'static str)]) -> HeaderMap {
    let mut h = HeaderMap::new();
    for (k, v) in pairs {
        h.append(*k, HeaderValue::from_static(v));
    }
    h
}

#[test]
fn untrusted_peers_are_the_visitor_whatever_they_forward() {
    let h = headers(&[
        ("x-forwarded-for", "203.0.113.9"),
        ("forwarded", "for=198.51.100.1"),
    ]);
    // No trusted proxies (the default): the header is the client's claim.
    assert_eq!(client_address(ip("192.0.2.7"), &h, &[]), ip("192.0.2.7"));
    // A peer outside the trusted ranges is not believed either.
    let trusted = nets(&["127.0.0.1/32", "10.0.0.0/8"]);
    assert_eq!(
        client_address(ip("192.0.2.7"), &h, &trusted),
        ip("192.0.2.7")
    );
}

#[test]
fn trusted_proxy_names_the_visitor() {
    let trusted = nets(&["127.0.0.1/32"]);
    let h = headers(&[("x-forwarded-for", "203.0.113.9")]);
    assert_eq!(
        client_address(ip("127.0.0.1"), &h, &trusted),
        ip("203.0.113.9")
    );
    // Without a header the proxy is all there is.
    assert_eq!(
        client_address(ip("127.0.0.1"), &HeaderMap::new(), &trusted),
        ip("127.0.0.1")
    );
}

#[test]
fn the_chain_is_read_from_the_right_and_spoofed_entries_ignored() {
    // The visitor wrote "1.1.1.1" itself; nginx appended the real address,
    // and a CDN edge (trusted too) came before nginx.
    let trusted = nets(&["127.0.0.1/32", "10.0.0.0/8"]);
    let h = headers(&[("x-forwarded-for", "1.1.1.1, 203.0.113.9, 10.1.2.3")]);
    assert_eq!(
        client_address(ip("127.0.0.1"), &h, &trusted),
        ip("203.0.113.9")
    );
    // Several header lines are one list.
    let h = headers(&[
        ("x-forwarded-for", "1.1.1.1"),
        ("x-forwarded-for", "203.0.113.9, 10.1.2.3"),
    ]);
    assert_eq!(
        client_address(ip("127.0.0.1"), &h, &trusted),
        ip("203.0.113.9")
    );
    // Everything trusted: the leftmost.
    let h = headers(&[("x-forwarded-for", "10.9.9.9, 10.1.2.3")]);
    assert_eq!(
        client_address(ip("127.0.0.1"), &h, &trusted),
        ip("10.9.9.9")
    );
    // Garbage stops the walk at the last trusted hop.
    let h = headers(&[("x-forwarded-for", "1.1.1.1, not-an-ip, 10.1.2.3")]);
    assert_eq!(
        client_address(ip("127.0.0.1"), &h, &trusted),
        ip("10.1.2.3")
    );
}

#[test]
fn forwarded_header_rfc_7239() {
    let trusted = nets(&["::1/128", "127.0.0.1/32"]);
    let h = headers(&[(
        "forwarded",
        "for=1.1.1.1, for=\"[2001:db8::7]:4711\";proto=https, for=127.0.0.1",
    )]);
    assert_eq!(client_address(ip("::1"), &h, &trusted), ip("2001:db8::7"));
    let h = headers(&[("forwarded", "proto=https;for=198.51.100.4:8080")]);
    assert_eq!(
        client_address(ip("127.0.0.1"), &h, &trusted),
        ip("198.51.100.4")
    );
    // X-Forwarded-For wins when both are there (nginx sets that one).
    let h = headers(&[
        ("forwarded", "for=198.51.100.4"),
        ("x-forwarded-for", "203.0.113.9"),
    ]);
    assert_eq!(
        client_address(ip("127.0.0.1"), &h, &trusted),
        ip("203.0.113.9")
    );
}
