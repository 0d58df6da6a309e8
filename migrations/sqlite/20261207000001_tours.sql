-- Guided tours (issue 44): a curator's ordered views of a model, each with a
-- title and text per language. A tour belongs to the model version it was
-- recorded on (its views are cameras in that version's coordinates); the
-- public sees the tours of the version it is served. The steps are kept as
-- one JSON array, so a reorder is one write. Keep in step with the other
-- backend's migration.
CREATE TABLE tour (
    id            INTEGER PRIMARY KEY,
    model_slug    TEXT    NOT NULL,
    model_version INTEGER NOT NULL CHECK (model_version >= 1),
    -- JSON language map {"en": "…", "pt": "…"}.
    title         TEXT    NOT NULL,
    -- JSON [{"view": "camera=…", "title": {…}, "text": {…}, "html": {…}}].
    steps         TEXT    NOT NULL,
    created_at    INTEGER NOT NULL,
    updated_at    INTEGER NOT NULL
);
CREATE INDEX tour_model ON tour (model_slug, model_version);
