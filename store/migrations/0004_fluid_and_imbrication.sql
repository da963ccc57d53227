-- Fluid forces: what later stages read of a job's fluid without decoding its stored spec,
-- filled at submission (NULL: buoyancy only, the first paper's protocol, as for every job
-- submitted before this migration); and the imbrication of a packing deposited with fluid
-- forces on (NULL for the others). Both are JSON the store does not look into.
ALTER TABLE jobs ADD COLUMN fluid TEXT CHECK (fluid IS NULL OR json_valid(fluid));
ALTER TABLE results ADD COLUMN imbrication TEXT CHECK (imbrication IS NULL OR json_valid(imbrication));
