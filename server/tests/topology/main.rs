//! Tests of the multi-instance topology (issue 24): the configuration file
//! and `--check-config`, the forwarded-address trust rule, every route's
//! cache headers, and coherence of two instances on one database. The
//! service suite's harness (test databases on both backends, a server on
//! port 0) is shared with `tests/service`.

#[allow(dead_code)]
#[path = "../service/harness.rs"]
mod harness;
#[allow(dead_code)]
#[path = "../service/proxy.rs"]
mod proxy;

mod cache_rules;
mod coherence;
mod config;
mod forwarded;
mod ui_strings;
