-- Quality issue (#5): every level's quality against the original, measured at
-- ingest with `vitrine ingest --quality` (codec/src/quality.rs). The level rows
-- already had `hausdorff` (symmetric Hausdorff distance over the bounding-box
-- diagonal) and `rmse` (now defined as the Lindstrom–Turk image RMSE, 0–255,
-- over 24 views); this adds Roy et al.'s colour RMSE (0–255; NULL when the
-- original or the level has no colour). All three are NULL for a level that
-- was not measured. How they were measured (image size, samples, time) is in
-- `compression.stats` under "quality". Keep in step with ../postgres/.
ALTER TABLE base_mesh ADD COLUMN roy_rmse REAL;
ALTER TABLE refinement_batch ADD COLUMN roy_rmse REAL;
