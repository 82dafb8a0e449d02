//! The batch's files (docs/collections.md): cache entries checked by key and checksum, an
//! unwritable cache used without storing, map files one-to-one with pairs, an output folder
//! held by one run with its settings.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use shapecorr::collection::{
    map_file, BasisCache, Batch, BatchSettings, OutputFolder, Outputs, Reading,
    DEFAULT_MEMORY_BYTES,
};
use shapecorr::options::Options;
use shapecorr::spectral::eigen::EigenParams;
use shapecorr::Shape;

use crate::common::icosphere;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "shapecorr-collection-{}-{name}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn sphere(levels: u32, squash: f64) -> Shape {
    let (v, t) = icosphere(levels);
    let v = v.into_iter().map(|[x, y, z]| [x, y, z * squash]).collect();
    Shape::mesh(v, &t).unwrap()
}

fn params() -> EigenParams {
    EigenParams {
        n_eigenpairs: 12,
        ..Default::default()
    }
}

fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn a_damaged_or_foreign_cache_entry_is_computed_again_and_replaced() {
    let dir = scratch("damaged");
    let cache = BasisCache {
        dir: Some(dir.clone()),
    };
    let (a, b) = (sphere(2, 1.0), sphere(2, 0.6));
    let (key_a, key_b) = ("a".repeat(64), "b".repeat(64));
    let first_a = cache.basis_for_key(Some(&key_a), &a, &params()).unwrap();
    let first_b = cache.basis_for_key(Some(&key_b), &b, &params()).unwrap();
    assert!(!first_a.from_cache && first_a.warning.is_none());
    let again = cache.basis_for_key(Some(&key_a), &a, &params()).unwrap();
    assert!(again.from_cache && again.warning.is_none());
    assert_eq!(again.basis.values, first_a.basis.values);

    let file_a = dir.join(format!("{key_a}.basis"));
    let good = std::fs::read(&file_a).unwrap();
    // Flipped exponent bits in stored doubles (the file stays well formed), then B's
    // valid entry under A's name.
    let mut flipped = good.clone();
    for i in 0..20 {
        flipped[200 + 8 * (30 * i) + 7] ^= 0x10;
    }
    let foreign = std::fs::read(dir.join(format!("{key_b}.basis"))).unwrap();
    for (damage, why) in [(flipped, "checksum"), (foreign, "another entry's key")] {
        std::fs::write(&file_a, damage).unwrap();
        let timed = cache.basis_for_key(Some(&key_a), &a, &params()).unwrap();
        assert!(!timed.from_cache, "{why}");
        let warning = timed.warning.expect("a warning");
        assert!(
            warning.contains(why) && warning.contains("computed again"),
            "{warning}"
        );
        assert_eq!(timed.basis.values, first_a.basis.values, "{why}");
        let replaced = cache.basis_for_key(Some(&key_a), &a, &params()).unwrap();
        assert!(replaced.from_cache && replaced.warning.is_none(), "{why}");
        assert_eq!(replaced.basis.values, first_a.basis.values, "{why}");
    }
    assert_ne!(first_b.basis.values, first_a.basis.values);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_entry_that_cannot_be_stored_is_a_warning_and_leaves_no_temporary_file() {
    let dir = scratch("unwritable");
    let cache = BasisCache {
        dir: Some(dir.clone()),
    };
    let shape = sphere(2, 1.0);
    let key = "c".repeat(64);
    // A folder where the entry goes: the rename fails, also for root.
    std::fs::create_dir(dir.join(format!("{key}.basis"))).unwrap();
    let timed = cache.basis_for_key(Some(&key), &shape, &params()).unwrap();
    assert!(!timed.from_cache);
    let warning = timed.warning.expect("a warning");
    assert!(warning.contains("could not be stored"), "{warning}");
    let reference = BasisCache::default()
        .basis_for_key(None, &shape, &params())
        .unwrap();
    assert_eq!(timed.basis.values, reference.basis.values);
    assert_eq!(entries(&dir), [format!("{key}.basis")]);

    // A cache "folder" that is a file: the basis is computed all the same.
    let file = dir.join("not-a-folder");
    std::fs::write(&file, b"x").unwrap();
    let cache = BasisCache {
        dir: Some(file.join("cache")),
    };
    let timed = cache.basis_for_key(Some(&key), &shape, &params()).unwrap();
    assert!(timed.warning.is_some());
    assert_eq!(timed.basis.values, reference.basis.values);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn map_files_are_one_to_one_with_pairs() {
    assert_ne!(map_file("x--y", "z"), map_file("x", "y--z"));
    assert_ne!(map_file("a/b", "c"), map_file("a__b", "c"));
    assert_eq!(map_file("tr-reg-000", "b"), "maps/tr-reg-000--b.u32");
    // Every name of up to 4 characters from an alphabet of separators and escapes.
    let alphabet = ['a', '-', '%', '/', '2'];
    let mut names = vec![String::new()];
    for length in 1..=4 {
        let mut next = Vec::new();
        for name in names.iter().filter(|n| n.chars().count() == length - 1) {
            for c in alphabet {
                next.push(format!("{name}{c}"));
            }
        }
        names.extend(next);
    }
    let mut files = HashSet::new();
    for a in &names {
        for b in &names {
            let file = map_file(a, b);
            assert!(!file[5..].contains('/'), "{file}");
            assert!(files.insert(file), "{a:?} {b:?}");
        }
    }
}

fn settings(k_max: i64, cache: &Path) -> BatchSettings {
    let mut options = Options::default();
    options
        .set_option("k_max", shapecorr::options::OptionValue::Int(k_max))
        .unwrap();
    BatchSettings {
        options,
        reading: Reading::default(),
        outputs: Outputs::Regions,
        cache_dir: cache.to_path_buf(),
        memory_bytes: DEFAULT_MEMORY_BYTES,
    }
}

#[test]
fn an_output_folder_is_held_by_one_run_with_one_set_of_settings() {
    let dir = scratch("folder");
    let out = dir.join("out");
    let first = OutputFolder::open(&out, &settings(8, &dir.join("c1"))).unwrap();
    let e = OutputFolder::open(&out, &settings(8, &dir.join("c1"))).unwrap_err();
    assert!(e.to_string().contains("another batch is running"), "{e}");
    drop(first);
    // Released: the same settings (another cache folder does not change answers) resume.
    let again = OutputFolder::open(&out, &settings(8, &dir.join("c2"))).unwrap();
    drop(again);
    let e = OutputFolder::open(&out, &settings(6, &dir.join("c1"))).unwrap_err();
    assert!(e.to_string().contains("other settings"), "{e}");
    // A folder of an earlier version is refused, not resumed.
    std::fs::write(out.join("batch.json"), r#"{"outputs":"regions"}"#).unwrap();
    let e = OutputFolder::open(&out, &settings(8, &dir.join("c1"))).unwrap_err();
    assert!(e.to_string().contains("earlier version"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_batch_refuses_landmarks_which_name_vertices_of_one_pair() {
    let dir = scratch("landmarks");
    let mut with_landmarks = settings(8, &dir.join("c"));
    with_landmarks.options.params.landmarks = vec![[0, 0], [5, 7]];
    let Err(e) = Batch::new(with_landmarks) else {
        panic!("landmarks accepted by a batch")
    };
    assert!(e.to_string().contains("landmarks"), "{e}");
    assert!(Batch::new(settings(8, &dir.join("c"))).is_ok());
    let _ = std::fs::remove_dir_all(&dir);
}
