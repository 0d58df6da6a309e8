//! Parts as the unit of streaming (issue 41): a charted stream's parts, each
//! addressable on its own, so a viewer fetches the charts it shows closely
//! and not whole batches.
//!
//! A part is a byte range of its stored batch, sliced by the lengths the
//! format writes (`vitrine_codec::PartedLayout`) without decoding. It is as
//! immutable as its batch: its strong ETag is the batch's digest and the
//! chart, its cache rule the batch's, and the batch's level cap applies to
//! it (an address names only its own batch's level and chart). The index
//! lists every part with the error it removes, measured at ingest
//! (`stream_part`), for the viewer to refine by screen-space error.
//!
//! A nested stream (format 6) is served the same way: a part's address is
//! its batch and its chart's position in the batch's phase, and each split
//! entry (`stream_split`) is a range of the head of its phase's first
//! batch, under that batch's cap. Its layout is read with the previous
//! parted batch's phase and chart count from the part rows
//! (`vitrine_codec::NestedLayout::parse_after`), never loading that batch.

use super::cache::{through, PartRows};
use super::error::{AppError, ErrorBody, LevelCappedBody};
use super::payload::{
    cache_control, level_bytes, not_modified, not_modified_response, parse_id, payload_response,
    within_cap, OCTET_STREAM,
};
use super::precompressed::{coding_headers, preferred};
use super::servable::{PathParams, ServableModel};
use super::visitor::{HintQuery, VisitorHints};
use super::AppState;
use axum::extract::State;
use axum::http::{HeaderMap, HeaderValue};
use axum::response::{IntoResponse, Response};
use bytes::Bytes;
use serde::{Deserialize, Serialize};
use std::sync::Arc;
use utoipa::{IntoParams, ToSchema};
use vitrine_codec::{NestedLayout, PartedLayout, NESTED_VERSION};

#[derive(Deserialize, IntoParams)]
#[into_params(parameter_in = Path)]
pub struct PartParams {
    /// Compression id, from the manifest.
    #[param(value_type = i64, minimum = 1)]
    id: String,
    /// Batch number, 1 … `last_level`: a parted batch.
    #[param(value_type = i64, minimum = 1)]
    iteration: String,
    /// Chart, 0 … `charts` − 1.
    #[param(value_type = i64, minimum = 0)]
    chart: String,
}

#[derive(Deserialize, IntoParams)]
#[into_params(parameter_in = Path)]
pub struct SplitParams {
    /// Compression id, from the manifest.
    #[param(value_type = i64, minimum = 1)]
    id: String,
    /// Batch number of the first parted batch of a phase after the first.
    #[param(value_type = i64, minimum = 1)]
    iteration: String,
    /// The chart split, by its position in the phase before.
    #[param(value_type = i64, minimum = 0)]
    parent: String,
}

#[derive(Deserialize, IntoParams)]
#[into_params(parameter_in = Path)]
pub struct HeadParams {
    /// Compression id, from the manifest.
    #[param(value_type = i64, minimum = 1)]
    id: String,
    /// Batch number of a parted batch.
    #[param(value_type = i64, minimum = 1)]
    iteration: String,
}

#[derive(Deserialize, IntoParams)]
#[into_params(parameter_in = Path)]
pub struct IndexParams {
    /// Compression id, from the manifest.
    #[param(value_type = i64, minimum = 1)]
    id: String,
}

/// Every part of a charted stream (format 5) or a nested one (format 6).
#[derive(Serialize, ToSchema)]
pub struct PartIndex {
    compression_id: i64,
    /// Charts the stream is cut into (a nested stream's top charts).
    charts: u32,
    /// Phases of nested charts: 1 for a charted stream.
    phases: u32,
    /// The first parted batch: before it the stream is whole batches, and
    /// its head (`head_url`) holds the charts' labels.
    first_level: u32,
    /// `/api/compressions/{id}/batches/{first_level}/head`.
    head_url: String,
    /// A part's address, `{level}` and `{chart}` to fill in.
    part_url: String,
    /// Batch by batch, chart by chart.
    parts: Vec<PartEntry>,
    /// A split entry's address, `{level}` (the first batch of the
    /// children's phase) and `{parent}` to fill in; nested streams only.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    split_url: Option<String>,
    /// A nested stream's split entries, batch by batch, parent by parent
    /// (absent for a charted stream): after every part of its phase, a
    /// chart is cut into its children by its entry.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    splits: Vec<SplitEntry>,
}

#[derive(Serialize, ToSchema)]
struct SplitEntry {
    /// The first batch of the children's phase, whose head holds it.
    level: u32,
    /// The chart split, by its position in the phase before.
    parent: u32,
    /// Its children: `first_child` … `first_child + children − 1` of the
    /// batch's phase.
    first_child: u32,
    children: u32,
    /// Bytes of the entry as served.
    bytes: u32,
}

#[derive(Serialize, ToSchema)]
struct PartEntry {
    level: u32,
    /// The chart's position in its phase.
    chart: u32,
    /// The chart's phase (0 in a charted stream).
    phase: u32,
    /// The chart's parent, by its position in the phase before (nested
    /// streams, phase ≥ 1).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    parent: Option<u32>,
    /// Bytes of the part as served (0: the chart sits this batch out).
    bytes: u32,
    /// Vertices it inserts.
    inserted: u32,
    /// The largest distance, in model units, from a vertex it inserts to
    /// the chart's coarser surface: divided by the distance to the camera
    /// and times the view's pixels per radian, the pixels it changes at
    /// most: the bound occlusion needs.
    error: f64,
    /// The distance within which 90 % of those vertices lie (`error` for a
    /// part measured before it was): what the viewer refines by.
    bulk_error: f64,
}

/// The index of a charted stream's parts.
#[utoipa::path(
    get,
    path = "/api/compressions/{id}/parts",
    params(IndexParams, HintQuery),
    responses(
        (status = 200, description = "The parts, with the error each removes", body = PartIndex),
        (status = 400, description = "Malformed id, query or `Authorization`", body = ErrorBody),
        (status = 401, description = "The token is unknown, revoked or expired", body = ErrorBody),
        (status = 404, description = "No such compression, or a plain stream (no parts)", body = ErrorBody),
        (status = 503, description = "Database unavailable or server overloaded", body = ErrorBody,
            headers(("Retry-After" = u64, description = "Seconds to wait before asking again"))),
    )
)]
pub async fn index(
    State(state): State<AppState>,
    PathParams(IndexParams { id }): PathParams<IndexParams>,
    hints: VisitorHints,
    request: HeaderMap,
) -> Result<Response, AppError> {
    let id = parse_id(&id, "compression id")?;
    let record = state.record_by_compression(id).await?;
    let ServableModel { record, .. } = ServableModel::decide(&state, record, &hints).await?;
    let stored = part_rows(&state, id).await?;
    let nested = record.stream_format == NESTED_VERSION;
    // Built and compressed once per compression and coding, off the
    // request task: a 25 M-vertex nested stream's index is some 8,000
    // entries (730 KB of JSON, 60 KB in brotli, 0.1 s to compress).
    let coding = preferred(&request);
    let body = match stored.index.ready(coding) {
        Some(body) => body,
        None => {
            let rows = stored.clone();
            tokio::task::spawn_blocking(move || {
                rows.index.encoded(coding, || {
                    let index = part_index(id, nested, &rows)?;
                    serde_json::to_vec(&index).map(Bytes::from).map_err(|e| {
                        AppError::Internal(format!("part index of compression {id}: {e}"))
                    })
                })
            })
            .await
            .map_err(|e| AppError::Internal(format!("part index of compression {id}: {e}")))??
        }
    };
    // As long-lived as the stream, but not immutable: a re-ingest of
    // the same compression id never happens, a curator's withdrawal may.
    let cache = if cache_control(&record, 0).starts_with("public") {
        "public, max-age=3600"
    } else {
        "private, max-age=3600"
    };
    let headers = [
        (axum::http::header::CACHE_CONTROL, cache),
        (axum::http::header::CONTENT_TYPE, "application/json"),
    ];
    // Sent as compressed above, not by the compression layer per request.
    let mut response = (headers, body).into_response();
    coding_headers(coding, response.headers_mut());
    Ok(response)
}

/// The index of a compression's parts, from its stored rows.
fn part_index(id: i64, nested: bool, stored: &PartRows) -> Result<PartIndex, AppError> {
    let rows = &stored.parts;
    let (Some(first), Some(charts), Some(phases)) = (
        rows.iter().map(|p| p.iteration).min(),
        rows.iter()
            .filter(|p| p.phase == 0)
            .map(|p| p.chart + 1)
            .max(),
        rows.iter().map(|p| p.phase + 1).max(),
    ) else {
        return Err(AppError::NotFound("parts"));
    };
    let splits: &[_] = if nested { &stored.splits } else { &[] };
    Ok(PartIndex {
        compression_id: id,
        charts,
        phases,
        first_level: first,
        head_url: format!("/api/compressions/{id}/batches/{first}/head"),
        part_url: format!("/api/compressions/{id}/batches/{{level}}/parts/{{chart}}"),
        parts: rows
            .iter()
            .map(|p| PartEntry {
                level: p.iteration,
                chart: p.chart,
                phase: p.phase,
                parent: p.parent,
                bytes: p.bytes,
                inserted: p.inserted,
                error: p.error,
                bulk_error: p.bulk_error.unwrap_or(p.error),
            })
            .collect(),
        split_url: nested
            .then(|| format!("/api/compressions/{id}/batches/{{level}}/splits/{{parent}}")),
        splits: splits
            .iter()
            .map(|s| SplitEntry {
                level: s.iteration,
                parent: s.parent,
                first_child: s.first_child,
                children: s.children,
                bytes: s.bytes,
            })
            .collect(),
    })
}

/// One chart's part of a parted batch.
#[utoipa::path(
    get,
    path = "/api/compressions/{id}/batches/{iteration}/parts/{chart}",
    params(PartParams, HintQuery),
    responses(
        (status = 200, description = "The part: its chart's passes in this batch (FORMAT.md, \
            \"Charted streams\"), for `ChartView::apply_part`", body = inline(super::payload::Binary),
            content_type = "application/octet-stream",
            headers(
                ("ETag" = String, description = "Strong ETag: the batch's digest and the chart"),
                ("Cache-Control" = String, description = "The batch's"))),
        (status = 304, description = "Not modified", headers(("ETag" = String), ("Cache-Control" = String))),
        (status = 400, description = "Malformed id, iteration, chart, query or `Authorization`", body = ErrorBody),
        (status = 401, description = "The token is unknown, revoked or expired", body = ErrorBody),
        (status = 403, description = "Above the visitor's cap, as the batch", body = LevelCappedBody),
        (status = 404, description = "No such compression, batch or chart, or a batch without parts", body = ErrorBody),
        (status = 429, description = "Above the cap set by server load", body = LevelCappedBody,
            headers(("Retry-After" = u64, description = "Seconds to wait before asking again"))),
        (status = 503, description = "Database unavailable or server overloaded", body = ErrorBody,
            headers(("Retry-After" = u64, description = "Seconds to wait before asking again"))),
    )
)]
pub async fn part(
    State(state): State<AppState>,
    PathParams(PartParams {
        id,
        iteration,
        chart,
    }): PathParams<PartParams>,
    hints: VisitorHints,
    headers: HeaderMap,
) -> Result<Response, AppError> {
    let chart = parse_chart(&chart)?;
    serve_piece(
        &state,
        &id,
        &iteration,
        &hints,
        &headers,
        Piece::Part(chart),
    )
    .await
}

/// One chart's split entry in a nested stream (format 6).
#[utoipa::path(
    get,
    path = "/api/compressions/{id}/batches/{iteration}/splits/{parent}",
    params(SplitParams, HintQuery),
    responses(
        (status = 200, description = "The split entry: the chart's children's count and labels \
            (FORMAT.md, \"Nested charts\"), for `NestedView::split`", body = inline(super::payload::Binary),
            content_type = "application/octet-stream",
            headers(
                ("ETag" = String, description = "Strong ETag: the batch's digest and the parent"),
                ("Cache-Control" = String, description = "The batch's"))),
        (status = 304, description = "Not modified", headers(("ETag" = String), ("Cache-Control" = String))),
        (status = 400, description = "Malformed id, iteration, parent, query or `Authorization`", body = ErrorBody),
        (status = 401, description = "The token is unknown, revoked or expired", body = ErrorBody),
        (status = 403, description = "Above the visitor's cap, as the batch", body = LevelCappedBody),
        (status = 404, description = "No such compression, batch or chart, or a batch that splits nothing", body = ErrorBody),
        (status = 429, description = "Above the cap set by server load", body = LevelCappedBody,
            headers(("Retry-After" = u64, description = "Seconds to wait before asking again"))),
        (status = 503, description = "Database unavailable or server overloaded", body = ErrorBody,
            headers(("Retry-After" = u64, description = "Seconds to wait before asking again"))),
    )
)]
pub async fn split(
    State(state): State<AppState>,
    PathParams(SplitParams {
        id,
        iteration,
        parent,
    }): PathParams<SplitParams>,
    hints: VisitorHints,
    headers: HeaderMap,
) -> Result<Response, AppError> {
    let parent = parse_chart(&parent)?;
    serve_piece(
        &state,
        &id,
        &iteration,
        &hints,
        &headers,
        Piece::Split(parent),
    )
    .await
}

/// The head of a parted batch: its chart count and, in the first parted
/// batch, the charts' labels (for `Decoder::into_view`); in a nested
/// stream, also its phase and, in a phase's first batch, the whole split.
#[utoipa::path(
    get,
    path = "/api/compressions/{id}/batches/{iteration}/head",
    params(HeadParams, HintQuery),
    responses(
        (status = 200, description = "The head", body = inline(super::payload::Binary),
            content_type = "application/octet-stream",
            headers(("ETag" = String), ("Cache-Control" = String))),
        (status = 304, description = "Not modified", headers(("ETag" = String), ("Cache-Control" = String))),
        (status = 400, description = "Malformed id, iteration, query or `Authorization`", body = ErrorBody),
        (status = 401, description = "The token is unknown, revoked or expired", body = ErrorBody),
        (status = 403, description = "Above the visitor's cap, as the batch", body = LevelCappedBody),
        (status = 404, description = "No such compression or batch, or a batch without parts", body = ErrorBody),
        (status = 429, description = "Above the cap set by server load", body = LevelCappedBody,
            headers(("Retry-After" = u64, description = "Seconds to wait before asking again"))),
        (status = 503, description = "Database unavailable or server overloaded", body = ErrorBody,
            headers(("Retry-After" = u64, description = "Seconds to wait before asking again"))),
    )
)]
pub async fn head(
    State(state): State<AppState>,
    PathParams(HeadParams { id, iteration }): PathParams<HeadParams>,
    hints: VisitorHints,
    headers: HeaderMap,
) -> Result<Response, AppError> {
    serve_piece(&state, &id, &iteration, &hints, &headers, Piece::Head).await
}

#[derive(Clone, Copy)]
enum Piece {
    Head,
    Part(usize),
    Split(usize),
}

fn parse_chart(text: &str) -> Result<usize, AppError> {
    let valid = !text.is_empty() && text.len() <= 4 && text.bytes().all(|b| b.is_ascii_digit());
    match text.parse::<usize>() {
        Ok(v) if valid => Ok(v),
        _ => Err(AppError::BadRequest(format!(
            "chart must be a non-negative integer, not {text:?}"
        ))),
    }
}

/// A piece of a parted batch, under the batch's cap, cache rule and digest.
async fn serve_piece(
    state: &AppState,
    id: &str,
    iteration: &str,
    hints: &VisitorHints,
    headers: &HeaderMap,
    piece: Piece,
) -> Result<Response, AppError> {
    let id = parse_id(id, "compression id")?;
    let iteration: u32 = parse_id(iteration, "iteration")?
        .try_into()
        .map_err(|_| AppError::NotFound("batch"))?;
    let record = state.record_by_compression(id).await?;
    let ServableModel { record, visitor } = ServableModel::decide(state, record, hints).await?;
    if iteration == 0 || iteration > record.batch_count() {
        return Err(AppError::NotFound("batch"));
    }
    within_cap(state, &record, &visitor, iteration)?;
    let digest = &record.levels[iteration as usize].sha256;
    let digest = &digest[..digest.len().min(32)];
    let tag = match piece {
        Piece::Head => format!("\"{digest}.h\""),
        Piece::Part(k) => format!("\"{digest}.p{k}\""),
        Piece::Split(k) => format!("\"{digest}.s{k}\""),
    };
    let etag =
        HeaderValue::from_str(&tag).unwrap_or_else(|_| HeaderValue::from_static("\"invalid\""));
    let cache = cache_control(&record, iteration);
    // The tag names these bytes only if they exist: answer before loading.
    if not_modified(headers, &etag) {
        return Ok(not_modified_response(etag, cache));
    }
    let bytes = level_bytes(state, &record, iteration).await?;
    let corrupt = |e: vitrine_codec::Error| {
        AppError::Internal(format!("stored batch {iteration} of compression {id}: {e}"))
    };
    let whole = AppError::NotFound("parts of this batch (a whole-mesh batch)");
    let (head, parts, splits) = if record.stream_format == NESTED_VERSION {
        let previous = previous_parted(state, id, iteration).await?;
        let layout = NestedLayout::parse_after(&bytes, previous)
            .map_err(corrupt)?
            .ok_or(whole)?;
        let splits = layout.splits.into_iter().map(|(_, r)| r).collect();
        (layout.head, layout.parts, splits)
    } else {
        let layout = PartedLayout::parse(&bytes).map_err(corrupt)?.ok_or(whole)?;
        (layout.head, layout.parts, Vec::new())
    };
    let range = match piece {
        Piece::Head => head,
        Piece::Part(k) => parts.get(k).cloned().ok_or(AppError::NotFound("chart"))?,
        Piece::Split(k) => splits
            .get(k)
            .cloned()
            .ok_or(AppError::NotFound("split entry"))?,
    };
    Ok(payload_response(
        bytes.slice(range),
        etag,
        cache,
        HeaderValue::from_static(OCTET_STREAM),
    ))
}

/// A compression's part and split rows, through the cache.
async fn part_rows(state: &AppState, id: i64) -> Result<Arc<PartRows>, AppError> {
    let storage = state.storage();
    let load = async {
        Ok(Arc::new(PartRows::new(
            storage.parts(id).await?,
            storage.splits(id).await?,
        )))
    };
    Ok(through(
        &state.caches().part_rows,
        state.metrics(),
        "parts",
        id,
        load,
    )
    .await?)
}

/// The phase and chart count of the parted batch before `iteration`, from
/// the part rows; `None` when `iteration` is the first parted batch.
async fn previous_parted(
    state: &AppState,
    id: i64,
    iteration: u32,
) -> Result<Option<(usize, usize)>, AppError> {
    let rows = part_rows(state, id).await?;
    Ok(iteration
        .checked_sub(1)
        .and_then(|before| rows.batch(before)))
}
