//! Job ids are hashes of the stored job: the same campaign file must give the same ids and the
//! same stored JSON as sedpack 0.1.0 gave (tests/fixtures/job-ids/ids-0.1.0.json), or resubmitted
//! campaigns would run every job again. The one exception is meant: `builtin:pebbles` were made
//! as angular as the Rhine scans since, so their digest, and with it the id of every job drawing
//! from them, changed (a resubmitted campaign runs those again, with the new pebbles).

mod common;

use common::{fixture, repo};
use sedpack::campaign::{Campaign, PlannedJob};
use serde_json::Value;

/// A campaign file of the repository, read as `sedpack run` reads it.
fn read(file: &str) -> Campaign {
    sedpack::campaign::read_campaign(repo(file).as_ref()).unwrap()
}

#[test]
fn campaign_files_give_the_job_ids_of_version_0_1_0() {
    let golden: serde_json::Map<String, Value> =
        serde_json::from_str(&std::fs::read_to_string(fixture("job-ids/ids-0.1.0.json")).unwrap()).unwrap();
    assert_eq!(golden.len(), 11);
    for (file, jobs) in &golden {
        let path = match file.split_once('/') {
            Some(("campaigns", _)) => repo(file).into(),
            Some(_) => fixture(file),
            None => fixture(&format!("job-ids/{file}")),
        };
        let campaign = sedpack::campaign::read_campaign(&path).unwrap_or_else(|e| panic!("{file}: {e:#}"));
        let jobs = jobs.as_array().unwrap();
        assert_eq!(campaign.jobs.len(), jobs.len(), "{file}");
        for (job, want) in campaign.jobs.iter().zip(jobs) {
            let mut changed = false;
            if let Some(spec) = want.get("spec") {
                let mut stored: Value = serde_json::from_str(&sedpack::stored::canonical_json(&job.spec)).unwrap();
                let meshes = &mut stored["packing"]["grains"]["meshes"];
                if meshes["source"] == "builtin:pebbles" {
                    let digest = &spec["packing"]["grains"]["meshes"]["digest"];
                    assert_ne!(&meshes["digest"], digest, "{file}: the pebbles of 0.1.0");
                    meshes["digest"] = digest.clone();
                    changed = true;
                }
                assert_eq!(&stored, spec, "{file}: the stored job");
            }
            assert_eq!(job.id == want["id"].as_str().unwrap(), !changed, "{file}");
        }
    }
    // The validation campaign's grid was reordered since (seeds outermost): the same jobs, in another order.
    let ids = |jobs: &[sedpack::campaign::PlannedJob]| {
        let mut ids: Vec<String> = jobs.iter().map(|j| j.id.clone()).collect();
        ids.sort();
        ids
    };
    let reordered = read("campaigns/validation-cylinder.yaml");
    let frozen = sedpack::campaign::read_campaign(&fixture("job-ids/validation-cylinder.yaml")).unwrap();
    assert_eq!(ids(&reordered.jobs), ids(&frozen.jobs));
}

#[test]
fn every_ready_campaign_file_reads_and_the_drag_study_pairs_its_seeds() {
    let dir = std::path::PathBuf::from(repo("campaigns"));
    let mut files = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "yaml") {
            let campaign = sedpack::campaign::read_campaign(&path).unwrap_or_else(|e| panic!("{e:#}"));
            assert!(!campaign.jobs.is_empty(), "{}", path.display());
            files += 1;
        }
    }
    assert!(files >= 10, "{files} campaign files");
    // With and without drag, the same eight seeds, otherwise the same jobs.
    let drag = read("campaigns/drag.yaml");
    let seeds = |wet: bool| {
        let mut seeds: Vec<u64> =
            drag.jobs.iter().filter(|j| j.spec.packing.fluid.is_some() == wet).map(|j| j.spec.packing.seed).collect();
        seeds.sort();
        seeds
    };
    assert_eq!(seeds(true), (1..=8).collect::<Vec<u64>>());
    assert_eq!(seeds(false), seeds(true));
    let first = &drag.jobs[0].spec.packing;
    for job in &drag.jobs {
        let p = &job.spec.packing;
        assert_eq!((&p.grains, &p.domain, &p.process), (&first.grains, &first.domain, &first.process));
    }
}

#[test]
fn the_table_6_and_7_campaigns_are_the_papers_setups() {
    // Every job of these studies is the paper's setup, so that `sedpack report` compares it
    // with the paper's row: Table 6 by size case in the cylinder, Table 7 at L = 0.1 m, and the
    // pebbles' repeats of U1 and U7 (meshes of their own forms, as the scans).
    let table6 =
        [("U1", 0.383), ("U3", 0.369), ("U5", 0.333), ("U7", 0.314), ("B30", 0.286), ("B50", 0.280), ("B70", 0.290)];
    let not_u1_u7: Vec<_> = table6.iter().filter(|r| !["U1", "U7"].contains(&r.0)).copied().collect();
    for (file, table, rows) in [
        ("campaigns/validation-cylinder.yaml", "Table 6", &table6[..]),
        ("campaigns/validation-periodic.yaml", "Table 7", &[("U7", 0.291), ("B50", 0.246)][..]),
        ("campaigns/validation-pebbles.yaml", "Table 7", &[("U7", 0.291)][..]),
        ("campaigns/validation-pebbles-cylinder.yaml", "Table 6", &[("U1", 0.383)][..]),
        ("campaigns/validation-contact-point.yaml", "Table 6", &[("U1", 0.383), ("U7", 0.314)][..]),
        ("campaigns/validation-cylinder-witness.yaml", "Table 6", &not_u1_u7[..]),
        ("campaigns/validation-periodic-witness.yaml", "Table 7", &[("U7", 0.291), ("B50", 0.246)][..]),
    ] {
        let campaign = read(file);
        assert_eq!(campaign.jobs.len(), 3 * rows.len(), "{file}");
        for job in &campaign.jobs {
            let case = job.spec.packing.grains.size.case().unwrap().name;
            let want = rows.iter().find(|r| r.0 == case).unwrap().1;
            // As planned, and as the report reads it back from the database (every value concrete).
            let stored =
                sedpack::stored::decode(sedpack::stored::format(&job.spec), &sedpack::stored::encode(&job.spec));
            for spec in [&job.spec, &stored.unwrap()] {
                let paper =
                    analysis::paper::simulated_porosity(&spec.packing).unwrap_or_else(|| panic!("{file}: {case}"));
                assert_eq!((paper.table.as_str(), paper.porosity), (table, want), "{file}: {case}");
            }
        }
    }
}

#[test]
fn the_shaking_study_is_table_5s_u7_and_table_6s_u7_but_for_t_s() {
    let study = read("campaigns/validation-shaking.yaml");
    let witness = read("campaigns/validation-contact-point.yaml");
    assert_eq!(study.jobs.len(), 9);
    for job in &study.jobs {
        let p = &job.spec.packing;
        let want =
            [(0.0, 0.323), (2.0, 0.309), (3.0, 0.309)].iter().find(|r| r.0 == p.process.shaking_duration).unwrap().1;
        let paper = analysis::paper::simulated_porosity(p).unwrap();
        assert_eq!((paper.table.as_str(), paper.porosity), ("Table 5", want));
        let mut one_second = p.clone();
        one_second.process.shaking_duration = 1.0;
        let table6 = witness
            .jobs
            .iter()
            .map(|j| &j.spec.packing)
            .find(|q| q.seed == p.seed && q.grains.size.case().map(|c| c.name) == Some("U7"));
        assert_eq!(&one_second, table6.unwrap(), "t_s = {} s, seed {}", p.process.shaking_duration, p.seed);
    }
}

#[test]
fn the_contact_point_studies_are_tables_6_and_7_with_only_the_contact_point_changed() {
    use solver::dem::ContactPoint;
    // Between them the two cylinder studies pour every case of Table 6 under the paper's rule.
    for (file, reference, jobs) in [
        ("campaigns/validation-contact-point.yaml", "campaigns/validation-cylinder.yaml", 6),
        ("campaigns/validation-cylinder-witness.yaml", "campaigns/validation-cylinder.yaml", 15),
        ("campaigns/validation-periodic-witness.yaml", "campaigns/validation-periodic.yaml", 6),
    ] {
        let study = read(file);
        let reference = read(reference);
        assert_eq!(study.jobs.len(), jobs, "{file}");
        for job in &study.jobs {
            let case = job.spec.packing.grains.size.case().map(|c| c.name);
            let witness = &job.spec.packing;
            assert_eq!(witness.contact_point, ContactPoint::Witness);
            assert_eq!(sedpack::stored::format(&job.spec), 4);
            let centre = reference
                .jobs
                .iter()
                .map(|j| &j.spec.packing)
                .find(|p| p.seed == witness.seed && p.grains.size.case().map(|c| c.name) == case)
                .unwrap();
            let mut same = witness.clone();
            same.contact_point = ContactPoint::CentreOfPressure;
            assert_eq!(&same, centre, "{file}: {case:?}, seed {}", witness.seed);
        }
    }
    // U7's seeds come before B50's: Table 7's three seeds of U7 fit before the long B50 packings.
    let periodic = read("campaigns/validation-periodic-witness.yaml");
    let order: Vec<(&str, u64)> =
        periodic.jobs.iter().map(|j| (j.spec.packing.grains.size.case().unwrap().name, j.spec.packing.seed)).collect();
    assert_eq!(order[..4], [("U7", 1), ("U7", 2), ("U7", 3), ("B50", 1)]);
}

#[test]
fn the_calibration_and_orientation_studies_are_the_contact_points_u1_with_one_change() {
    use solver::dem::Calibration;
    use solver::packing::{Orientation, PackingSpec};
    let witness = read("campaigns/validation-contact-point.yaml");
    type Undo = fn(&mut PackingSpec) -> bool;
    let studies: [(&str, Undo); 2] = [
        ("campaigns/validation-calibration.yaml", |p| {
            std::mem::replace(&mut p.calibration, Calibration::Discrete) == Calibration::Continuous
        }),
        ("campaigns/validation-orientation.yaml", |p| {
            std::mem::replace(&mut p.process.orientation, Orientation::Random) == Orientation::Upright
        }),
    ];
    for (file, undo) in studies {
        let study = read(file);
        assert_eq!(study.jobs.len(), 3, "{file}");
        for job in &study.jobs {
            let changed = &job.spec.packing;
            // Eq. 11 as printed and upright new grains are the paper's and its software's own:
            // the report compares the studies with Table 6.
            let paper = analysis::paper::simulated_porosity(changed).unwrap();
            assert_eq!((paper.table.as_str(), paper.porosity), ("Table 6", 0.383), "{file}");
            let reference = witness
                .jobs
                .iter()
                .map(|j| &j.spec.packing)
                .find(|p| p.seed == changed.seed && p.grains.size.case().map(|c| c.name) == Some("U1"))
                .unwrap();
            let mut same = changed.clone();
            assert!(undo(&mut same), "{file}: the study's change");
            assert_eq!(&same, reference, "{file}: seed {}", changed.seed);
        }
    }
}

/// The grid study is Table 6's U5 and B50 of validation-cylinder-witness with only the grid
/// changed, stored in format 6, and still the paper's setup for the report.
#[test]
fn the_grid_study_is_the_witness_cylinders_u5_and_b50_on_the_close_packed_grid() {
    use solver::packing::Grid;
    let study = read("campaigns/validation-rain-grid.yaml");
    let reference = read("campaigns/validation-cylinder-witness.yaml");
    assert_eq!(study.jobs.len(), 6);
    for job in &study.jobs {
        let changed = &job.spec.packing;
        assert_eq!(sedpack::stored::format(&job.spec), 6);
        let case = changed.grains.size.case().map(|c| c.name);
        let paper = analysis::paper::simulated_porosity(changed).unwrap();
        let expected = if case == Some("U5") { 0.333 } else { 0.280 };
        assert_eq!((paper.table.as_str(), paper.porosity), ("Table 6", expected), "{case:?}");
        let cubic = reference
            .jobs
            .iter()
            .map(|j| &j.spec.packing)
            .find(|p| p.seed == changed.seed && p.grains.size.case().map(|c| c.name) == case)
            .unwrap();
        let mut same = changed.clone();
        assert_eq!(std::mem::replace(&mut same.process.grid, Grid::Cubic), Grid::Hcp);
        assert_eq!(&same, cubic, "{case:?}, seed {}", changed.seed);
    }
}

#[test]
fn table_11_draws_the_rhine_forms_and_the_scans_study_is_the_packing_it_ran_before() {
    use solver::dem::ContactPoint;
    use solver::grain::form_distribution::RHINE_FORMS;
    use solver::packing::FormSpec;
    let table11 = read("campaigns/validation-rhine-forms.yaml");
    let scans = read("campaigns/validation-scans-periodic.yaml");
    assert_eq!((table11.jobs.len(), scans.jobs.len()), (3, 3));
    for (drawn, own) in table11.jobs.iter().zip(&scans.jobs) {
        assert_eq!(drawn.spec.packing.grains.form, FormSpec::Distribution(RHINE_FORMS));
        assert_eq!(own.spec.packing.grains.form, FormSpec::Own);
        assert_eq!(drawn.spec.packing.contact_point, ContactPoint::Witness);
        let mut same = drawn.spec.packing.clone();
        same.grains.form = FormSpec::Own;
        same.contact_point = ContactPoint::CentreOfPressure;
        assert_eq!(same, own.spec.packing, "the two differ by the form and the contact point alone");
        // Both are in the setting of the paper's models, so their reports compare them with Eq. 23.
        assert!(analysis::paper::in_model_setting(&drawn.spec.packing));
        assert!(analysis::paper::in_model_setting(&own.spec.packing));
    }
    // The job that validation-rhine-forms.yaml stored for seed 1 before it had its `form:` key
    // (sedpack 3268e0c, 2026-12-03, id b59357dd4a9c6c64), as the database holds it: the scans
    // study's seed 1 but for the campaign's name, which is part of a job.
    let before: Value = serde_json::from_str(
        &std::fs::read_to_string(fixture("job-ids/validation-rhine-forms-seed-1-3268e0c.json")).unwrap(),
    )
    .unwrap();
    let mut stored = sedpack::stored::encode(&scans.jobs[0].spec);
    assert_eq!(stored["job"]["name"], "validation-scans-periodic");
    stored["job"]["name"] = "validation-rhine-forms".into();
    assert_eq!(stored, before);
}

/// Table 7's U7 packings under the paper's contact point, seeds in order: the studies of the
/// scans' forms and of the pebbles each change this setup in one respect.
fn table_7s_u7_under_the_witness() -> Vec<solver::packing::PackingSpec> {
    let table7 = read("campaigns/validation-periodic-witness.yaml");
    let u7 = table7.jobs.into_iter().filter(|j| j.spec.packing.grains.size.case().unwrap().name == "U7");
    u7.map(|j| j.spec.packing).collect()
}

#[test]
fn table_11s_u7_is_table_7s_u7_with_the_rhine_forms_shaken_6_s() {
    use solver::grain::form_distribution::RHINE_FORMS;
    use solver::packing::FormSpec;
    let u7 = read("campaigns/validation-rhine-forms-u7.yaml");
    let scans = table_7s_u7_under_the_witness();
    assert_eq!((u7.jobs.len(), scans.len()), (3, 3));
    for (drawn, own) in u7.jobs.iter().zip(scans) {
        let drawn = &drawn.spec.packing;
        assert_eq!(drawn.grains.form, FormSpec::Distribution(RHINE_FORMS));
        assert_eq!(drawn.process.shaking_duration, 6.0);
        // The report compares it with Eq. 24 at its grains' measured forms.
        assert!(analysis::paper::in_model_setting(drawn));
        let mut same = drawn.clone();
        same.grains.form = FormSpec::Own;
        same.process.shaking_duration = own.process.shaking_duration;
        assert_eq!(same, own, "differs by more than the forms and the shaking, seed {}", drawn.seed);
    }
}

#[test]
fn table_11s_u7_shaken_1_s_differs_from_table_11s_u7_by_the_shaking_and_from_table_7s_by_the_forms() {
    use solver::packing::FormSpec;
    let short = read("campaigns/validation-rhine-forms-u7-shaken-1s.yaml");
    let long = read("campaigns/validation-rhine-forms-u7.yaml");
    let scans = table_7s_u7_under_the_witness();
    assert_eq!((short.jobs.len(), long.jobs.len(), scans.len()), (3, 3, 3));
    for ((short, long), own) in short.jobs.iter().zip(&long.jobs).zip(&scans) {
        let short = &short.spec.packing;
        // Table 7's own shaking, so the pair with Table 7's U7 differs by the forms alone.
        assert_eq!(short.process.shaking_duration, own.process.shaking_duration);
        assert_eq!(short.process.shaking_duration, 1.0);
        let mut shaken_longer = short.clone();
        shaken_longer.process.shaking_duration = long.spec.packing.process.shaking_duration;
        assert_eq!(&shaken_longer, &long.spec.packing, "differs by more than the shaking, seed {}", short.seed);
        let mut own_forms = short.clone();
        own_forms.grains.form = FormSpec::Own;
        assert_eq!(&own_forms, own, "differs by more than the forms, seed {}", short.seed);
    }
}

#[test]
fn the_cylinders_rhine_forms_study_is_table_6s_u1_and_u7_under_the_witness_but_for_the_forms() {
    use solver::grain::form_distribution::RHINE_FORMS;
    use solver::packing::FormSpec;
    let study = read("campaigns/validation-cylinder-rhine-forms.yaml");
    let witness = read("campaigns/validation-contact-point.yaml");
    assert_eq!(study.jobs.len(), 6);
    // U1's jobs keep the ids they were stored under (6173343) before U7 joined the grid.
    let u1: Vec<&str> = study
        .jobs
        .iter()
        .filter(|j| j.spec.packing.grains.size.case().map(|c| c.name) == Some("U1"))
        .map(|j| j.id.as_str())
        .collect();
    assert_eq!(u1, ["d0996bcdaf1a4f13", "999914214b5adebf", "9ac2ec31060c3d5c"]);
    for job in &study.jobs {
        let drawn = &job.spec.packing;
        assert_eq!(drawn.grains.form, FormSpec::Distribution(RHINE_FORMS));
        // Table 6's measured porosity stays attached for the report; the paper simulated the
        // cylinder with its 63 scans keeping their own forms, so no simulated row is this setup.
        assert!(job.spec.experiment.is_some());
        assert!(analysis::paper::simulated_porosity(drawn).is_none());
        let own = witness
            .jobs
            .iter()
            .map(|j| &j.spec.packing)
            .find(|p| p.seed == drawn.seed && p.grains.size.case() == drawn.grains.size.case())
            .unwrap();
        let mut same = drawn.clone();
        same.grains.form = FormSpec::Own;
        assert_eq!(&same, own, "differs by more than the forms, seed {}", drawn.seed);
    }
}

/// The jobs of `pebbles` and `scans`, paired, after asserting that each pair differs only in
/// the library (the pebbles, simplified to 300 faces as the scans are).
fn only_the_library_differs(pebbles: &str, scans: &str, jobs: usize) -> Vec<(PlannedJob, PlannedJob)> {
    let (pebbles, scans) = (read(pebbles), read(scans));
    assert_eq!((pebbles.jobs.len(), scans.jobs.len()), (jobs, jobs));
    for (pebble, scan) in pebbles.jobs.iter().zip(&scans.jobs) {
        let library = pebble.spec.packing.grains.meshes.as_ref().unwrap();
        assert_eq!((library.source.as_str(), library.faces), ("builtin:pebbles", 300));
        let mut same = pebble.spec.packing.clone();
        same.grains.meshes = scan.spec.packing.grains.meshes.clone();
        assert_eq!(&same, &scan.spec.packing, "differs by more than the library, seed {}", scan.spec.packing.seed);
    }
    pebbles.jobs.into_iter().zip(scans.jobs).collect()
}

#[test]
fn the_pebbles_with_drawn_forms_are_the_cylinders_rhine_forms_but_for_the_library() {
    let pairs = only_the_library_differs(
        "campaigns/validation-pebbles-cylinder-rhine-forms.yaml",
        "campaigns/validation-cylinder-rhine-forms.yaml",
        6,
    );
    for (pebble, scan) in pairs {
        assert_eq!(pebble.parameters, scan.parameters);
        assert!(pebble.spec.experiment.is_some());
    }
}

#[test]
fn fig_10_under_the_witness_is_the_single_form_study_with_only_the_contact_point_changed() {
    use solver::dem::ContactPoint;
    let study = read("campaigns/validation-single-forms-witness.yaml");
    let centre = read("campaigns/validation-single-forms.yaml");
    assert_eq!((study.jobs.len(), centre.jobs.len()), (30, 30));
    for (witness, centre) in study.jobs.iter().zip(&centre.jobs) {
        let mut same = witness.spec.packing.clone();
        assert_eq!(same.contact_point, ContactPoint::Witness);
        same.contact_point = ContactPoint::CentreOfPressure;
        assert_eq!(same, centre.spec.packing, "seed {}", same.seed);
        assert_eq!(witness.parameters, centre.parameters);
    }
}

#[test]
fn the_pebbles_with_drawn_forms_in_table_7s_u7_are_its_rhine_forms_shaken_1_s_but_for_the_library() {
    let pairs = only_the_library_differs(
        "campaigns/validation-pebbles-periodic-rhine-forms.yaml",
        "campaigns/validation-rhine-forms-u7-shaken-1s.yaml",
        3,
    );
    for (pebble, scan) in pairs {
        assert_ne!(pebble.id, scan.id);
    }
}

#[test]
fn the_periodic_pebble_studies_are_table_11_and_table_7s_u7_poured_from_the_pebbles() {
    use solver::packing::FormSpec;
    let table11 = read("campaigns/validation-rhine-forms.yaml");
    // Table 11's setting is the paper's form models' own, so the report compares it with Eq. 23.
    for (file, scans, in_models) in [
        (
            "campaigns/validation-pebbles-periodic.yaml",
            table11.jobs.into_iter().map(|j| j.spec.packing).collect(),
            true,
        ),
        ("campaigns/validation-pebbles.yaml", table_7s_u7_under_the_witness(), false),
    ] {
        let pebbles = read(file);
        if in_models {
            assert!(pebbles.jobs.iter().all(|j| analysis::paper::in_model_setting(&j.spec.packing)), "{file}");
        }
        assert_eq!((pebbles.jobs.len(), scans.len()), (3, 3), "{file}");
        for (scan, pebble) in scans.iter().zip(&pebbles.jobs) {
            let library = pebble.spec.packing.grains.meshes.as_ref().unwrap();
            assert_eq!((library.source.as_str(), library.faces), ("builtin:pebbles", 300));
            // The pebbles carry Table 2's forms themselves, so nothing rescales them.
            assert_eq!(pebble.spec.packing.grains.form, FormSpec::Own);
            let mut same = scan.clone();
            same.grains.form = FormSpec::Own;
            same.grains.meshes = pebble.spec.packing.grains.meshes.clone();
            assert_eq!(same, pebble.spec.packing, "{file}: differs by more than the meshes, seed {}", same.seed);
        }
    }
}
