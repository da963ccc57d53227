-- The grains and mass a packing created in each sieve class, against the curve's mass fractions:
-- [{"lower": m, "upper": m, "asked": fraction, "grains": n, "mass": kg}], JSON the store does not
-- look into. NULL for results stored before this migration.
ALTER TABLE results ADD COLUMN size_classes TEXT CHECK (size_classes IS NULL OR json_valid(size_classes));
