-- Rights: who made a scan and on what terms it may be reused, per version.
-- The viewer shows them, the model page states them, GLB downloads carry
-- them. NULL when not recorded. `licence` is an identifier from the list in
-- server/src/storage/curator/rights.rs (CC-BY-4.0, CC0-1.0, InC, ...).
-- Keep in step with the other backend's migration.
ALTER TABLE model ADD COLUMN credit TEXT;
ALTER TABLE model ADD COLUMN licence TEXT;
