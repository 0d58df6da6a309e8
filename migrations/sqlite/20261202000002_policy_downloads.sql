-- Downloads (issue 19): a policy may let visitors download a level they may
-- reach as one GLB (`GET /api/models/{slug}/download.glb?level=K`), for
-- <model-viewer>, AR viewers and social platforms. Off for the existing
-- policies; two new policies have it on. The original file is never served.
-- Keep in step with ../postgres/.
ALTER TABLE audience_policy ADD COLUMN downloads BOOLEAN NOT NULL DEFAULT 0;

INSERT INTO audience_policy
    (name, description, public_access, public_max_vertex_fraction, public_full_resolution, token_full_resolution, downloads)
VALUES
    ('open-download', 'Everyone may fetch every level and download it as GLB.', 1, 1.0, 1, 1, 1),
    ('exhibition-download', 'Public exhibition, and a level within the visitor''s cap may be downloaded as GLB.', 1, 1.0, 0, 1, 1);
