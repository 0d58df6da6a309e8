-- Colour issue (#5): a CCC mapping has three images. The low-resolution copy
-- of the colour atlas (every side divided by the parameters' `low_res_factor`)
-- is a 'colour' texture like the full one, told apart by the column that
-- points to it. Keep in step with ../postgres/ (same column, only types differ).
-- A column rather than a new `kind`: SQLite cannot alter a CHECK constraint.
ALTER TABLE texture_mapping ADD COLUMN colour_low_texture_id INTEGER REFERENCES texture (id);

-- The texture route looks a texture up through the mapping that uses it.
CREATE INDEX texture_mapping_cell ON texture_mapping (cell_texture_id);
CREATE INDEX texture_mapping_colour ON texture_mapping (colour_texture_id);
CREATE INDEX texture_mapping_colour_low ON texture_mapping (colour_low_texture_id);
