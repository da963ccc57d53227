-- Where a packing stood when its checkpoint was written, for `sedpack status`: its phase
-- (generation, shaking, damping), its grains and the fraction of the target mass created.
-- NULL for checkpoints written before this migration: status then gives the simulated time only.
ALTER TABLE checkpoints ADD COLUMN phase TEXT;
ALTER TABLE checkpoints ADD COLUMN grains INTEGER CHECK (grains IS NULL OR grains >= 0);
ALTER TABLE checkpoints ADD COLUMN mass_created REAL CHECK (mass_created IS NULL OR mass_created >= 0);
