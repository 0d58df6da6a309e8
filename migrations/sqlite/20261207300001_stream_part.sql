-- One chart's part of a parted batch of a charted stream (format 5): the
-- unit a viewer streams when it refines where the visitor looks (issue 41).
-- The bytes stay in refinement_batch; the service slices a part out of its
-- batch by the lengths the format writes. `error` is the largest distance,
-- in model units, from a vertex the part inserts to the chart's coarser
-- surface, measured at ingest (codec/core/src/parts/). Keep in step with the
-- other backend's migration.
CREATE TABLE stream_part (
    compression_id INTEGER NOT NULL REFERENCES compression (id) ON DELETE CASCADE,
    iteration      INTEGER NOT NULL CHECK (iteration >= 1),
    chart          INTEGER NOT NULL CHECK (chart >= 0),
    byte_len       INTEGER NOT NULL CHECK (byte_len >= 0),
    inserted       INTEGER NOT NULL CHECK (inserted >= 0),
    error          REAL    NOT NULL CHECK (error >= 0),
    PRIMARY KEY (compression_id, iteration, chart)
);
