-- Curators (issue 22): token scopes, the up axis, unit and bounds of each
-- version, thumbnails rendered at ingest, annotations, and upload jobs.
-- Keep in step with ../postgres/ (same tables, same columns; only types differ).

-- A researcher token opens researcher-only levels; a curator token publishes
-- and annotates. Tokens made before this migration are researchers' tokens.
ALTER TABLE access_token ADD COLUMN scope TEXT NOT NULL DEFAULT 'researcher'
    CHECK (scope IN ('researcher', 'curator'));

-- Which model axis points up (x, y, z, -x, -y, -z); NULL for versions
-- ingested before this migration (the viewer then assumes +y).
ALTER TABLE model ADD COLUMN up_axis TEXT;
-- The unit of model coordinates (mm, cm, m, in), NULL when unknown.
ALTER TABLE model ADD COLUMN unit TEXT;
-- JSON {"min": [x, y, z], "max": [x, y, z]} in the stream's (dequantized)
-- coordinates; NULL for versions ingested before this migration.
ALTER TABLE model ADD COLUMN bounds TEXT;

-- A picture of the version, rendered at ingest (codec/quality's rasteriser).
CREATE TABLE thumbnail (
    model_id   INTEGER PRIMARY KEY REFERENCES model (id) ON DELETE CASCADE,
    media_type TEXT    NOT NULL,
    width      INTEGER NOT NULL,
    height     INTEGER NOT NULL,
    byte_len   INTEGER NOT NULL,
    sha256     TEXT    NOT NULL,
    bytes      BLOB    NOT NULL,
    created_at INTEGER NOT NULL
);

-- A curator's hotspot: a point and normal in model coordinates (so it stays
-- on the surface at every level, and belongs to the slug, not one version).
CREATE TABLE annotation (
    id         INTEGER PRIMARY KEY,
    model_slug TEXT    NOT NULL,
    title      TEXT    NOT NULL,
    -- Markdown source, and the sanitised HTML rendered from it.
    body       TEXT    NOT NULL,
    html       TEXT    NOT NULL,
    -- JSON [x, y, z]; the normal is stored normalised.
    position   TEXT    NOT NULL,
    normal     TEXT    NOT NULL,
    -- JSON object (a saved camera) or NULL.
    saved_view TEXT,
    created_at INTEGER NOT NULL,
    updated_at INTEGER NOT NULL
);
CREATE INDEX annotation_model ON annotation (model_slug);

-- An upload's ingest, run in the background; any instance can report it.
CREATE TABLE ingest_job (
    id            INTEGER PRIMARY KEY,
    slug          TEXT    NOT NULL,
    title         TEXT    NOT NULL,
    -- The uploaded file's name as the client gave it (shown, never a path).
    source_name   TEXT    NOT NULL,
    state         TEXT    NOT NULL CHECK (state IN ('queued', 'running', 'done', 'failed')),
    progress      REAL    NOT NULL DEFAULT 0 CHECK (progress BETWEEN 0 AND 1),
    stage         TEXT    NOT NULL DEFAULT '',
    -- The importer's or encoder's message when failed.
    error         TEXT,
    model_version INTEGER,
    token_id      INTEGER REFERENCES access_token (id),
    created_at    INTEGER NOT NULL,
    updated_at    INTEGER NOT NULL
);
CREATE INDEX ingest_job_created ON ingest_job (created_at);
