-- Nested streams (format 6, issue 41): a part's chart has a phase and,
-- past phase 0, a parent (its position in the phase before); charted
-- streams (format 5) keep phase 0 and no parent. A split entry cuts a
-- chart of phase d − 1 into its children of phase d; it lies in the head
-- of phase d's first batch (`iteration`), and the service slices it out
-- by the lengths the format writes, as it does parts. Keep in step with
-- the other backend's migration.
ALTER TABLE stream_part ADD COLUMN phase INTEGER NOT NULL DEFAULT 0 CHECK (phase >= 0);
ALTER TABLE stream_part ADD COLUMN parent INTEGER CHECK (parent >= 0);
CREATE TABLE stream_split (
    compression_id INTEGER NOT NULL REFERENCES compression (id) ON DELETE CASCADE,
    iteration      INTEGER NOT NULL CHECK (iteration >= 1),
    parent         INTEGER NOT NULL CHECK (parent >= 0),
    first_child    INTEGER NOT NULL CHECK (first_child >= 0),
    children       INTEGER NOT NULL CHECK (children >= 1),
    byte_len       INTEGER NOT NULL CHECK (byte_len >= 0),
    PRIMARY KEY (compression_id, iteration, parent)
);
