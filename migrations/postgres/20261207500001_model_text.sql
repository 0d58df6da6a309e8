-- A model version's texts per language (issue 43): `model.language` is the
-- BCP 47 tag of the version's own title, description and credit (NULL when
-- not stated); `model_text` holds a translation per further language, each
-- field NULL where the default text stands. Pages, the manifest, oEmbed and
-- IIIF pick the visitor's language with a fallback to the default
-- (server/src/storage/texts/). Keep in step with the other backend's migration.
ALTER TABLE model ADD COLUMN language TEXT;
CREATE TABLE model_text (
    model_id    BIGINT NOT NULL REFERENCES model (id) ON DELETE CASCADE,
    language    TEXT   NOT NULL,
    title       TEXT,
    description TEXT,
    credit      TEXT,
    PRIMARY KEY (model_id, language)
);
