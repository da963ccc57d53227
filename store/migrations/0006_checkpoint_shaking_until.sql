-- While the packing shakes, the simulated time its shaking ends (t_s after the last grain was
-- created), so that `sedpack status` says how much of the shaking is left. NULL in the other
-- phases and for checkpoints written before this migration.
ALTER TABLE checkpoints ADD COLUMN shaking_until REAL;
