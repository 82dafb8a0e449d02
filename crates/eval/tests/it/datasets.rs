//! The dataset registry (layouts, pair lists, ground truth, mirror maps, clear errors), the
//! on-disk eigenbasis cache and the resumable result log of `bench all`, on small datasets
//! written here in each layout from generated figures.

use std::path::{Path, PathBuf};

use shapecorr::synth::{figure_poses, FigureKind, Proportions};
use shapecorr::ReadAs;
use shapecorr::{EigenParams, Shape};
use shapecorr_eval::bench_store::{BasisCache, ResultLog, ShapeStore};
use shapecorr_eval::datasets::{discover, read_pairs, Dataset, Layout, Pair};

fn temp(name: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("shapecorr-datasets-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write(path: &Path, text: &str) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, text).unwrap();
}

fn lines(values: impl IntoIterator<Item = u32>) -> String {
    values.into_iter().map(|v| format!("{v}\n")).collect()
}

/// Two poses of a small humanoid (shared vertex order).
fn poses() -> Vec<shapecorr::synth::FigureMesh> {
    figure_poses(FigureKind::Humanoid, 600, Proportions::default(), &[0, 2]).unwrap()
}

fn write_off(path: &Path, mesh: &shapecorr::synth::FigureMesh, order: &[usize]) {
    // Vertices in `order` (a remeshing stand-in): new vertex i is old vertex order[i].
    let mut inverse = vec![0u32; order.len()];
    for (new, &old) in order.iter().enumerate() {
        inverse[old] = new as u32;
    }
    let mut text = format!("OFF\n{} {} 0\n", order.len(), mesh.triangles.len());
    for &old in order {
        let v = mesh.vertices[old];
        text.push_str(&format!("{} {} {}\n", v[0], v[1], v[2]));
    }
    for t in &mesh.triangles {
        text.push_str(&format!(
            "3 {} {} {}\n",
            inverse[t[0] as usize], inverse[t[1] as usize], inverse[t[2] as usize]
        ));
    }
    write(path, &text);
}

#[test]
fn shared_order_layouts_faust_scape_and_tosca() {
    let root = temp("shared");
    let meshes = poses();
    let n = meshes[0].vertices.len();
    for (dataset, names) in [
        ("faust", ["tr_reg_000", "tr_reg_001"]),
        ("scape", ["mesh000", "mesh001"]),
        ("tosca", ["cat0", "cat1"]),
    ] {
        for (name, mesh) in names.iter().zip(&meshes) {
            let path = root.join(dataset).join(format!("{name}.ply"));
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            shapecorr::shape::io::write_ply(&path, &mesh.vertices, &mesh.triangles, None).unwrap();
        }
        write(
            &root.join("pairs").join(format!("{dataset}.txt")),
            &format!(
                "# source\ttarget\tcategory\n{}\t{}\tsame\n",
                names[0], names[1]
            ),
        );
    }
    // A reversed mirror map for faust, a per-class one for tosca, none for scape.
    let reversed: Vec<u32> = (0..n as u32).rev().collect();
    write(
        &root.join("faust/template_mirror.txt"),
        &lines(reversed.clone()),
    );
    write(&root.join("tosca/cat_mirror.txt"), &lines(reversed.clone()));

    let (found, skipped) = discover(&root).unwrap();
    let names: Vec<&str> = found.iter().map(|d| d.name.as_str()).collect();
    assert_eq!(names, ["faust", "scape", "tosca"]);
    assert!(skipped.is_empty(), "{skipped:?}");
    assert_eq!(found[0].layout, Layout::SharedOrder);
    assert_eq!(found[1].layout, Layout::SharedOrder);
    assert_eq!(found[2].layout, Layout::SharedOrderPerClass);

    for d in &found {
        let pairs = read_pairs(&d.pairs_file(&root)).unwrap();
        let p = &pairs[0];
        let a = Shape::read(&d.shape_path(&p.source).unwrap(), ReadAs::Auto).unwrap();
        assert_eq!(a.n_vertices(), n);
        let (truth, flipped) = d.ground_truth(&p.source, &p.target, n, n).unwrap();
        assert_eq!(truth.len(), n);
        assert!(truth.iter().all(|&(x, y)| x == y));
        match d.name.as_str() {
            "scape" => assert!(flipped.is_none()),
            _ => {
                let flipped = flipped.unwrap();
                assert!(flipped
                    .iter()
                    .all(|&(x, y)| y as usize == n - 1 - x as usize));
            }
        }
        // Vertex counts that differ are an error, not a wrong score.
        assert!(d.ground_truth(&p.source, &p.target, n, n - 1).is_err());
    }
    // TOSCA: no ground truth across classes.
    let tosca = Dataset::open(&root, "tosca").unwrap();
    let e = tosca.ground_truth("cat0", "dog1", n, n).unwrap_err();
    assert!(e.to_string().contains("different classes"), "{e}");
    // A mirror map of the wrong length names the file.
    write(&root.join("faust/template_mirror.txt"), &lines(0..5));
    let faust = Dataset::open(&root, "faust").unwrap();
    let e = faust
        .ground_truth("tr_reg_000", "tr_reg_001", n, n)
        .unwrap_err();
    assert!(e.to_string().contains("template_mirror.txt"), "{e}");
    // Missing shapes say what was tried.
    let e = faust.shape_path("tr_reg_099").unwrap_err().to_string();
    assert!(e.contains("tr_reg_099") && e.contains(".off"), "{e}");
}

#[test]
fn vts_layout_maps_remeshed_shapes() {
    let root = temp("vts");
    let meshes = poses();
    let n = meshes[0].vertices.len();
    // Two "remeshings": the same surface with vertices in different orders.
    let order_a: Vec<usize> = (0..n).collect();
    let order_b: Vec<usize> = (0..n).map(|i| (i * 7 + 3) % n).collect();
    assert_eq!(
        {
            let mut s = order_b.clone();
            s.sort();
            s
        },
        order_a,
        "7 must be coprime to n = {n}"
    );
    write_off(&root.join("shrec_r/off/a.off"), &meshes[0], &order_a);
    write_off(&root.join("shrec_r/off/b.off"), &meshes[1], &order_b);
    // Template points 0, 10, 20, ...: their (1-based) vertex in each shape.
    let template: Vec<usize> = (0..n).step_by(10).collect();
    let position_b = |old: usize| order_b.iter().position(|&o| o == old).unwrap();
    write(
        &root.join("shrec_r/corres/a.vts"),
        &lines(template.iter().map(|&t| t as u32 + 1)),
    );
    write(
        &root.join("shrec_r/corres/b.vts"),
        &lines(template.iter().map(|&t| position_b(t) as u32 + 1)),
    );
    write(&root.join("pairs/shrec_r.txt"), "a\tb\tall\n");

    let d = Dataset::open(&root, "shrec_r").unwrap();
    assert_eq!(d.layout, Layout::Vts);
    let a = Shape::read(&d.shape_path("a").unwrap(), ReadAs::Auto).unwrap();
    let b = Shape::read(&d.shape_path("b").unwrap(), ReadAs::Auto).unwrap();
    let (truth, flipped) = d
        .ground_truth("a", "b", a.n_vertices(), b.n_vertices())
        .unwrap();
    assert!(flipped.is_none());
    assert_eq!(truth.len(), template.len());
    // Each pair joins the same original vertex.
    for &(x, y) in &truth {
        assert_eq!(order_b[y as usize], order_a[x as usize]);
    }
    // Indices are 1-based: a 0 is rejected with the line number.
    write(&root.join("shrec_r/corres/b.vts"), "0\n");
    let e = d.ground_truth("a", "b", n, n).unwrap_err().to_string();
    assert!(e.contains("line 1") && e.contains("b.vts"), "{e}");
    // Rows that do not pair up are an error.
    write(&root.join("shrec_r/corres/b.vts"), "1\n2\n");
    assert!(d.ground_truth("a", "b", n, n).is_err());
    // Layout detection from the folder (an unknown name with corres/).
    std::fs::rename(root.join("shrec_r"), root.join("other")).unwrap();
    assert_eq!(Dataset::open(&root, "other").unwrap().layout, Layout::Vts);
}

#[test]
fn template_index_layout_with_mirror() {
    let root = temp("template");
    let meshes = poses();
    let n = meshes[0].vertices.len();
    let order_b: Vec<usize> = (0..n).rev().collect();
    write_off(
        &root.join("remeshed/shapes/a.off"),
        &meshes[0],
        &(0..n).collect::<Vec<_>>(),
    );
    write_off(&root.join("remeshed/shapes/b.off"), &meshes[1], &order_b);
    // The template is the original vertex order; shape a is the template itself.
    write(&root.join("remeshed/template/a.txt"), &lines(0..n as u32));
    write(
        &root.join("remeshed/template/b.txt"),
        &lines(order_b.iter().map(|&o| o as u32)),
    );
    let mirror: Vec<u32> = (0..n as u32).map(|t| (t + 1) % n as u32).collect();
    write(
        &root.join("remeshed/template_mirror.txt"),
        &lines(mirror.clone()),
    );
    let d = Dataset::open(&root, "remeshed").unwrap();
    assert_eq!(d.layout, Layout::TemplateIndex);
    let (truth, flipped) = d.ground_truth("a", "b", n, n).unwrap();
    assert_eq!(truth.len(), n);
    for &(x, y) in &truth {
        assert_eq!(order_b[y as usize], x as usize);
    }
    // Mirrored: B's vertex y with template t pairs with A's vertex of template mirror[t].
    let flipped = flipped.unwrap();
    for &(x, y) in &flipped {
        assert_eq!(x, mirror[order_b[y as usize]]);
    }
    // A template file of the wrong length is an error naming it.
    write(&root.join("remeshed/template/b.txt"), &lines(0..3));
    let e = d.ground_truth("a", "b", n, n).unwrap_err().to_string();
    assert!(e.contains("b.txt") && e.contains("3 entries"), "{e}");
}

#[test]
fn missing_and_unknown_datasets_are_clear_errors() {
    let root = temp("missing");
    let e = Dataset::open(&root, "faust").unwrap_err().to_string();
    assert!(
        e.contains("dataset folder not found") && e.contains("SHAPECORR_DATA"),
        "{e}"
    );
    assert!(discover(&root).unwrap_err().to_string().contains("pairs/"));
    // A folder with nothing recognisable.
    std::fs::create_dir_all(root.join("empty")).unwrap();
    write(&root.join("pairs/empty.txt"), "a\tb\n");
    let e = Dataset::open(&root, "empty").unwrap_err().to_string();
    assert!(e.contains("cannot tell the dataset's layout"), "{e}");
    let (found, skipped) = discover(&root).unwrap();
    assert!(found.is_empty());
    assert_eq!(skipped.len(), 1);
    // Pair list lines need two names.
    write(&root.join("pairs/bad.txt"), "onlyone\n");
    let e = read_pairs(&root.join("pairs/bad.txt"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("line 1"), "{e}");
}

#[test]
fn eigenbasis_cache_returns_the_same_basis_and_survives_damage() {
    let root = temp("cache");
    let mesh = &poses()[0];
    let path = root.join("shape.ply");
    shapecorr::shape::io::write_ply(&path, &mesh.vertices, &mesh.triangles, None).unwrap();
    let shape = Shape::read(&path, ReadAs::Auto).unwrap();
    let params = EigenParams {
        n_eigenpairs: 20,
        ..EigenParams::default()
    };
    let cache = BasisCache {
        dir: Some(root.join("cache")),
    };
    let first = cache
        .basis(&path, &shape, "points=false|repair=true", &params)
        .unwrap();
    assert!(!first.from_cache);
    let second = cache
        .basis(&path, &shape, "points=false|repair=true", &params)
        .unwrap();
    assert!(second.from_cache);
    assert_eq!(second.seconds, first.seconds, "the original time is kept");
    assert_eq!(first.basis.values, second.basis.values);
    assert_eq!(first.basis.mass, second.basis.mass);
    assert_eq!(first.basis.input_area, second.basis.input_area);
    assert_eq!(first.basis.vectors, second.basis.vectors);
    // Other parameters or other file bytes: another key.
    let bytes = std::fs::read(&path).unwrap();
    let key = BasisCache::key(&bytes, "points=false|repair=true", &params);
    assert_ne!(
        key,
        BasisCache::key(&bytes, "points=true|repair=true", &params)
    );
    let more = EigenParams {
        n_eigenpairs: 21,
        ..params.clone()
    };
    assert_ne!(
        key,
        BasisCache::key(&bytes, "points=false|repair=true", &more)
    );
    let threads = EigenParams {
        threads: 1,
        ..params.clone()
    };
    assert_eq!(
        key,
        BasisCache::key(&bytes, "points=false|repair=true", &threads),
        "threads do not change results"
    );
    let mut edited = bytes.clone();
    *edited.last_mut().unwrap() ^= 1;
    assert_ne!(
        key,
        BasisCache::key(&edited, "points=false|repair=true", &params)
    );
    // A damaged cache file is recomputed, not trusted.
    let file = root.join("cache").join(format!("{key}.basis"));
    let len = std::fs::metadata(&file).unwrap().len();
    let f = std::fs::OpenOptions::new().write(true).open(&file).unwrap();
    f.set_len(len - 8).unwrap();
    let third = cache
        .basis(&path, &shape, "points=false|repair=true", &params)
        .unwrap();
    assert!(!third.from_cache);
    assert_eq!(third.basis.values, first.basis.values);
}

/// `bench p2p --basis-cache DIR`: the first run writes both eigenbases to DIR, the second
/// reads them back and scores the same.
#[test]
fn pointwise_bench_keeps_its_eigenbases_in_the_cache() {
    let root = temp("p2p-cache");
    for (name, mesh) in ["tr_reg_000", "tr_reg_001"].iter().zip(&poses()) {
        let path = root.join("faust").join(format!("{name}.ply"));
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        shapecorr::shape::io::write_ply(&path, &mesh.vertices, &mesh.triangles, None).unwrap();
    }
    let pairs = root.join("pairs/faust.txt");
    write(
        &pairs,
        "# source\ttarget\tcategory\ntr_reg_000\ttr_reg_001\tsame\n",
    );
    let cache_dir = root.join("bases");
    let run = || {
        shapecorr_eval::bench_pointwise::bench_pointwise(
            &root,
            &pairs,
            &shapecorr::correspondence::Params::default(),
            &shapecorr::maps::pointwise::PointwiseParams::default(),
            0,
            Some(&["regions".to_string()]),
            None,
            BasisCache {
                dir: Some(cache_dir.clone()),
            },
            &mut |_, _, _| {},
        )
        .unwrap()
    };
    let written = || -> Vec<std::time::SystemTime> {
        let mut times: Vec<_> = std::fs::read_dir(&cache_dir)
            .unwrap()
            .map(|e| e.unwrap().metadata().unwrap().modified().unwrap())
            .collect();
        times.sort();
        times
    };
    let first = run();
    let before = written();
    assert_eq!(before.len(), 2, "one cached eigenbasis per shape");
    let second = run();
    assert_eq!(
        written(),
        before,
        "the second run reads the cache, writes nothing"
    );
    let (a, b) = (&first[0].scores[0], &second[0].scores[0]);
    assert_eq!(a.error.mean, b.error.mean);
    assert!(a.error.mean < 0.1, "mean error {}", a.error.mean);
}

#[test]
fn shape_store_loads_once_and_cuts_nothing() {
    let root = temp("store");
    let meshes = poses();
    for (name, mesh) in ["tr_reg_000", "tr_reg_001"].iter().zip(&meshes) {
        let path = root.join("faust").join(format!("{name}.ply"));
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        shapecorr::shape::io::write_ply(&path, &mesh.vertices, &mesh.triangles, None).unwrap();
    }
    let d = Dataset::open(&root, "faust").unwrap();
    let params = EigenParams {
        n_eigenpairs: 12,
        ..EigenParams::default()
    };
    let mut store = ShapeStore::new(d, params, BasisCache::default());
    store.load("tr_reg_000", true, false).unwrap();
    assert_eq!(store.basis("tr_reg_000").basis.len(), 12);
    assert!(store.get("tr_reg_000").heat.is_none());
    store.load("tr_reg_000", false, true).unwrap();
    assert!(store.get("tr_reg_000").heat.is_some());
    store.retain(&[]);
    assert!(store.load("tr_reg_002", false, false).is_err());
}

#[test]
fn result_log_resumes_and_drops_a_cut_line() {
    let root = temp("log");
    let path = root.join("logs/results.jsonl");
    let pair = |i: usize| Pair {
        source: format!("s{i}"),
        target: format!("t{i}"),
        category: "c".into(),
    };
    {
        let (mut log, done) = ResultLog::open::<Pair>(&path).unwrap();
        assert!(done.is_empty());
        for i in 0..3 {
            log.append(&pair(i)).unwrap();
        }
    }
    let (_, done) = ResultLog::open::<Pair>(&path).unwrap();
    assert_eq!(done, vec![pair(0), pair(1), pair(2)]);
    // An interruption in the middle of a line: that line is dropped and the file repaired.
    let mut text = std::fs::read_to_string(&path).unwrap();
    text.push_str("{\"source\":\"s3\",\"tar");
    std::fs::write(&path, &text).unwrap();
    {
        let (mut log, done) = ResultLog::open::<Pair>(&path).unwrap();
        assert_eq!(done.len(), 3);
        log.append(&pair(4)).unwrap();
    }
    let (_, done) = ResultLog::open::<Pair>(&path).unwrap();
    assert_eq!(done, vec![pair(0), pair(1), pair(2), pair(4)]);
    // A damaged line in the middle is an error that names the line.
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replacen("s1", "s1\"x", 1);
    std::fs::write(&path, text).unwrap();
    let e = ResultLog::open::<Pair>(&path).err().unwrap().to_string();
    assert!(e.contains("line 2"), "{e}");
}
