-- An annotation's title and text in further languages (issue 43): JSON
-- {"pt": {"title": "…", "text": "…", "html": "…"}}, NULL when none. The
-- annotation's own `language` keys its `title` and `body`. The viewer shows
-- the visitor's language with a fallback to the annotation's own; IIIF
-- serves every language (server/src/service/iiif/web_annotation.rs).
-- Keep in step with the other backend's migration.
ALTER TABLE annotation ADD COLUMN translations TEXT;
