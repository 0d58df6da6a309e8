-- The language of an annotation's title and text (a BCP 47 tag such as
-- `en` or `pt-BR`), NULL when not stated. IIIF manifests serve it as the
-- key of the annotation's language maps, and an import keeps it
-- (server/src/service/iiif/). Keep in step with the other backend's migration.
ALTER TABLE annotation ADD COLUMN language TEXT;
