-- What later stages need from a job's stored spec, in typed columns filled at submission: the
-- format the spec is stored in (the runner decodes it by that), and the measured porosity the
-- report compares with (NULL when the campaign gives none; a NULL std: no spread given).
ALTER TABLE jobs ADD COLUMN format INTEGER NOT NULL DEFAULT 1;
ALTER TABLE jobs ADD COLUMN experiment_porosity REAL;
ALTER TABLE jobs ADD COLUMN experiment_std REAL CHECK (experiment_std IS NULL OR experiment_porosity IS NOT NULL);

-- Jobs submitted before this migration are of format 1, sedpack 0.1.0's, whose experiment is
-- read from the spec here, once.
UPDATE jobs SET experiment_porosity = json_extract(spec, '$.experiment.porosity'),
                experiment_std = json_extract(spec, '$.experiment.std');
