-- The executor a campaign's jobs are handed to, as JSON written by the caller ({"kind": "slurm",
-- …}); NULL: the workers of `sedpack run` on the submitting machine, as before this migration.
ALTER TABLE campaigns ADD COLUMN executor TEXT CHECK (executor IS NULL OR json_valid(executor));
