-- A part's bulk error (issue 41): the distance, in model units, within
-- which 90 % of the vertices it inserts lie from the chart's coarser
-- surface (`error` stays the largest, the bound occlusion needs). A viewer
-- refines by the bulk: the largest of a scan's part is set by its noisiest
-- vertex. NULL for parts measured before it: `vitrine models` names those
-- models to ingest again, and the service falls back to `error`. Keep in
-- step with the other backend's migration.
ALTER TABLE stream_part ADD COLUMN bulk_error REAL CHECK (bulk_error >= 0);
