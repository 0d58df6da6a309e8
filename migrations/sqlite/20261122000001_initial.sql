-- Vitrine schema, SQLite flavour. Keep in step with ../postgres/ (same tables,
-- same columns; only types differ). Thesis table names (Mendes 2014, §6.3) in
-- brackets. Times are Unix milliseconds; digests are lowercase hex SHA-256.

-- Who may fetch how much of a model: public exhibition vs. researchers with a token.
CREATE TABLE audience_policy (
    id                         INTEGER PRIMARY KEY,
    name                       TEXT    NOT NULL UNIQUE,
    description                TEXT    NOT NULL DEFAULT '',
    -- Visitors without a token may see the model at all.
    public_access              BOOLEAN NOT NULL,
    -- Public cap: the highest level with at most this fraction of the full level's vertices.
    public_max_vertex_fraction REAL    NOT NULL CHECK (public_max_vertex_fraction BETWEEN 0 AND 1),
    -- May the public reach the last (full-resolution) level?
    public_full_resolution     BOOLEAN NOT NULL,
    -- May token holders reach it?
    token_full_resolution      BOOLEAN NOT NULL
);

INSERT INTO audience_policy
    (name, description, public_access, public_max_vertex_fraction, public_full_resolution, token_full_resolution)
VALUES
    ('exhibition', 'Public exhibition: every level but the full-resolution one; researchers with a token get all.', 1, 1.0, 0, 1),
    ('open', 'Everyone may fetch every level.', 1, 1.0, 1, 1),
    ('researchers', 'Only visitors with a token see the model.', 0, 0.0, 0, 1);

-- [tb_modelo] One row per ingested version of a model; the slug's visible
-- version is its highest 'ready' one. Rows only appear when an ingest commits.
CREATE TABLE model (
    id                INTEGER PRIMARY KEY,
    slug              TEXT    NOT NULL,
    version           INTEGER NOT NULL CHECK (version >= 1),
    title             TEXT    NOT NULL,
    description       TEXT    NOT NULL DEFAULT '',
    policy_id         INTEGER NOT NULL REFERENCES audience_policy (id),
    -- Level the quality study judged sufficient; NULL: first level with >= 20 %
    -- of the vertices (thesis §6.5–6.6). Load caps fall toward it.
    good_enough_level INTEGER CHECK (good_enough_level >= 0),
    -- File name only: the original file is never stored or served.
    source_name       TEXT,
    source_vertices   INTEGER NOT NULL,
    source_faces      INTEGER NOT NULL,
    status            TEXT    NOT NULL DEFAULT 'ready' CHECK (status IN ('ready', 'withdrawn')),
    created_at        INTEGER NOT NULL,
    UNIQUE (slug, version)
);

-- [tb_textura_celulas, tb_textura_colorida] Cell texture (the cubic cell
-- complex) and colour texture, one table told apart by `kind`.
CREATE TABLE texture (
    id         INTEGER PRIMARY KEY,
    kind       TEXT    NOT NULL CHECK (kind IN ('cell', 'colour')),
    media_type TEXT    NOT NULL,
    width      INTEGER,
    height     INTEGER,
    byte_len   INTEGER NOT NULL,
    sha256     TEXT    NOT NULL,
    bytes      BLOB    NOT NULL,
    created_at INTEGER NOT NULL
);

-- [tb_mapeamento_ccc] A colour mapping of a model: its cell and colour textures
-- and the complex's parameters (JSON, defined by the colour issue).
CREATE TABLE texture_mapping (
    id                INTEGER PRIMARY KEY,
    model_id          INTEGER NOT NULL REFERENCES model (id) ON DELETE CASCADE,
    cell_texture_id   INTEGER REFERENCES texture (id),
    colour_texture_id INTEGER REFERENCES texture (id),
    parameters        TEXT    NOT NULL DEFAULT '{}',
    created_at        INTEGER NOT NULL
);

-- [tb_compressao] One compression run: options, statistics, level table summary.
CREATE TABLE compression (
    id                INTEGER PRIMARY KEY,
    model_id          INTEGER NOT NULL REFERENCES model (id) ON DELETE CASCADE,
    mapping_id        INTEGER REFERENCES texture_mapping (id),
    codec_version     INTEGER NOT NULL,
    options           TEXT    NOT NULL,
    stats             TEXT    NOT NULL DEFAULT '{}',
    quantization_bits INTEGER NOT NULL,
    has_colour        BOOLEAN NOT NULL,
    batch_count       INTEGER NOT NULL,
    final_vertices    INTEGER NOT NULL,
    final_faces       INTEGER NOT NULL,
    stream_bytes      INTEGER NOT NULL,
    encode_ms         INTEGER NOT NULL,
    created_at        INTEGER NOT NULL
);
CREATE INDEX compression_model ON compression (model_id);

-- [tb_modelo_base] Stream header plus base mesh chunk: what a viewer fetches first.
CREATE TABLE base_mesh (
    compression_id INTEGER PRIMARY KEY REFERENCES compression (id) ON DELETE CASCADE,
    vertices       INTEGER NOT NULL,
    faces          INTEGER NOT NULL,
    byte_len       INTEGER NOT NULL,
    sha256         TEXT    NOT NULL,
    -- Quality against the original, filled in by the quality issue.
    hausdorff      REAL,
    rmse           REAL,
    bytes          BLOB    NOT NULL
);

-- [tb_iteracao] Refinement batch `iteration` (1-based) of a compression, with
-- the counts after applying it.
CREATE TABLE refinement_batch (
    compression_id INTEGER NOT NULL REFERENCES compression (id) ON DELETE CASCADE,
    iteration      INTEGER NOT NULL CHECK (iteration >= 1),
    vertices       INTEGER NOT NULL,
    faces          INTEGER NOT NULL,
    byte_len       INTEGER NOT NULL,
    sha256         TEXT    NOT NULL,
    hausdorff      REAL,
    rmse           REAL,
    bytes          BLOB    NOT NULL,
    PRIMARY KEY (compression_id, iteration)
);

-- Researcher access. Only the token's SHA-256 is stored.
CREATE TABLE access_token (
    id           INTEGER PRIMARY KEY,
    token_sha256 TEXT    NOT NULL UNIQUE,
    label        TEXT    NOT NULL,
    -- NULL: every model.
    model_slug   TEXT,
    expires_at   INTEGER,
    revoked_at   INTEGER,
    created_at   INTEGER NOT NULL
);
