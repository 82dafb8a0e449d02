/*
 * C API tests: the whole life cycle on generated figures, every error path, cancellation,
 * concurrent calls on shared handles, the version check, the confidence and warning of a
 * result (in range, a warning exactly when doubtful, none unverified or for NULL), and the
 * point-to-point map (a permuted copy of a figure is mapped back to the identity).
 * Compiled as C99 with -Wall -Wextra -Wpedantic -Werror against include/shapecorr.h and
 * linked against the built libshapecorr.so by tests/c/run.sh (every test plain and under
 * ASan+UBSan, the ownership tests it names under valgrind).
 *
 * `test_api NAME...` runs the named tests only; `test_api --list` names them all.
 * SHAPECORR_TEST_QUICK=1 (used under valgrind) makes the figures smaller and the thread
 * test shorter; the checks are the same.
 */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "shapecorr.h"

#ifndef CARGO_VERSION
#error "compile with -DCARGO_VERSION=\"x.y.z\" (the version in Cargo.toml)"
#endif

static int failures = 0;
static int checks = 0;

#define CHECK(cond, ...)                                                                  \
    do {                                                                                  \
        checks++;                                                                         \
        if (!(cond)) {                                                                    \
            failures++;                                                                   \
            fprintf(stderr, "FAIL %s:%d: %s: ", __FILE__, __LINE__, #cond);               \
            fprintf(stderr, __VA_ARGS__);                                                 \
            fprintf(stderr, "\n");                                                        \
        }                                                                                 \
    } while (0)

#define CHECK_STATUS(call, expected)                                                      \
    do {                                                                                  \
        sc_status got_ = (call);                                                          \
        CHECK(got_ == (expected), "got status %u (%s), expected %u; last error: %s",      \
              (unsigned)got_, sc_status_str(got_), (unsigned)(expected), sc_last_error()); \
    } while (0)

static int quick = 0;

static double now_seconds(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static sc_shape *figure(const char *kind, uint32_t pose) {
    sc_shape *shape = NULL;
    CHECK_STATUS(sc_shape_new_figure(kind, pose, quick ? 700 : 2500, &shape), SC_STATUS_OK);
    return shape;
}

/* ---------------------------------------------------------------- version and statuses */

static void test_version(void) {
    char expected[64];
    snprintf(expected, sizeof expected, "%d.%d.%d", SC_VERSION_MAJOR, SC_VERSION_MINOR,
             SC_VERSION_PATCH);
    CHECK(strcmp(expected, CARGO_VERSION) == 0, "header %s vs Cargo.toml %s", expected,
          CARGO_VERSION);
    CHECK(strcmp(sc_version(), CARGO_VERSION) == 0, "runtime %s vs Cargo.toml %s",
          sc_version(), CARGO_VERSION);
    CHECK(sc_version_major() == SC_VERSION_MAJOR, "major");
    CHECK(sc_version_minor() == SC_VERSION_MINOR, "minor");
    CHECK(sc_version_patch() == SC_VERSION_PATCH, "patch");
    CHECK(sc_abi_version() == SC_ABI_VERSION, "abi %u", sc_abi_version());
}

static void test_status_text(void) {
    CHECK(strcmp(sc_status_str(SC_STATUS_OK), "success") == 0, "%s", sc_status_str(0));
    CHECK(strstr(sc_status_str(SC_STATUS_CANCELLED), "cancel") != NULL, "cancelled text");
    CHECK(strstr(sc_status_str(SC_STATUS_RESOURCE_LIMIT), "resource limit") != NULL, "%s",
          sc_status_str(SC_STATUS_RESOURCE_LIMIT));
    CHECK(SC_STATUS_RESOURCE_LIMIT == 19, "a new status takes the next number");
    CHECK(strcmp(sc_status_str(77777), "unknown status") == 0, "unknown status text");
    CHECK(sc_last_error() != NULL, "last error is never NULL");
}

/* ---------------------------------------------------------------------------- options */

static void test_options(void) {
    size_t n = sc_option_count();
    size_t i;
    sc_params *params = NULL;
    int64_t k = 0;
    double gap = 0.0;
    bool one_to_one = false;
    CHECK(n >= 10, "%zu options", n);
    for (i = 0; i < n; i++) {
        CHECK(sc_option_name(i) != NULL && strlen(sc_option_name(i)) > 0, "name %zu", i);
        CHECK(sc_option_doc(i) != NULL, "doc %zu", i);
        CHECK(sc_option_type(i) <= SC_OPTION_BOOL, "type %zu", i);
    }
    CHECK(sc_option_name(n) == NULL, "past the end");
    CHECK(sc_option_type(n) == UINT32_MAX, "past the end");

    CHECK_STATUS(sc_params_new(NULL), SC_STATUS_NULL_ARGUMENT);
    CHECK_STATUS(sc_params_new(&params), SC_STATUS_OK);
    /* Defaults are the documented ones. */
    CHECK_STATUS(sc_params_get_int(params, "k_min", &k), SC_STATUS_OK);
    CHECK(k == 5, "default k_min %lld", (long long)k);
    CHECK_STATUS(sc_params_get_double(params, "gap_ratio", &gap), SC_STATUS_OK);
    CHECK(fabs(gap - 0.9) < 1e-12, "default gap %g", gap);
    CHECK_STATUS(sc_params_get_bool(params, "one_to_one", &one_to_one), SC_STATUS_OK);
    CHECK(one_to_one, "one-to-one on by default");

    CHECK_STATUS(sc_params_set_int(params, "k_min", 6), SC_STATUS_OK);
    CHECK_STATUS(sc_params_get_int(params, "k_min", &k), SC_STATUS_OK);
    CHECK(k == 6, "k_min read back %lld", (long long)k);
    CHECK_STATUS(sc_params_set_double(params, "gap_ratio", 0.85), SC_STATUS_OK);
    CHECK_STATUS(sc_params_get_double(params, "gap_ratio", &gap), SC_STATUS_OK);
    CHECK(gap == 0.85, "gap read back %g", gap);

    /* Errors: unknown name, wrong type, bad value, NULLs; values unchanged after each. */
    CHECK_STATUS(sc_params_set_int(params, "k_mni", 6), SC_STATUS_UNKNOWN_OPTION);
    CHECK(strstr(sc_last_error(), "k_mni") != NULL, "message names the option: %s",
          sc_last_error());
    CHECK(strstr(sc_last_error(), "k_min") != NULL, "message lists the options");
    CHECK_STATUS(sc_params_set_double(params, "k_min", 6.0), SC_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(sc_params_set_int(params, "k_min", -1), SC_STATUS_INVALID_PARAMETER);
    CHECK_STATUS(sc_params_set_double(params, "gap_ratio", NAN), SC_STATUS_INVALID_PARAMETER);
    CHECK_STATUS(sc_params_set_bool(params, "gap_ratio", true), SC_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(sc_params_get_bool(params, "k_min", &one_to_one), SC_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(sc_params_set_int(NULL, "k_min", 6), SC_STATUS_NULL_ARGUMENT);
    CHECK_STATUS(sc_params_set_int(params, NULL, 6), SC_STATUS_NULL_ARGUMENT);
    CHECK_STATUS(sc_params_get_int(params, "k_min", NULL), SC_STATUS_NULL_ARGUMENT);
    CHECK_STATUS(sc_params_get_int(params, "k_min", &k), SC_STATUS_OK);
    CHECK(k == 6, "k_min unchanged by failed calls: %lld", (long long)k);
    CHECK_STATUS(sc_params_get_double(params, "gap_ratio", &gap), SC_STATUS_OK);
    CHECK(gap == 0.85, "gap unchanged by failed calls: %g", gap);
    sc_params_free(params);
    sc_params_free(NULL);
}

/* Every option at extreme values (0, -1, 1e12, NaN, +-inf, 1e300) gives OK or
   INVALID_PARAMETER naming that option, never PANIC or an abort; the range functions agree. */
static void test_option_extremes(void) {
    static const double extremes[] = {0.0, -1.0, 1e12, 1e300, -1e300};
    size_t n = sc_option_count(), i, j;
    sc_params *params = NULL;
    CHECK_STATUS(sc_params_new(&params), SC_STATUS_OK);
    CHECK(isnan(sc_option_min(n)) && isnan(sc_option_max(n)), "range past the end is NaN");
    for (i = 0; i < n; i++) {
        const char *name = sc_option_name(i);
        double lo = sc_option_min(i), hi = sc_option_max(i);
        CHECK(lo <= hi, "%s: range [%g, %g]", name, lo, hi);
        for (j = 0; j < sizeof extremes / sizeof extremes[0] + 3; j++) {
            double v = j < 5 ? extremes[j] : j == 5 ? NAN : j == 6 ? INFINITY : hi * 2.0 + 1.0;
            sc_status st;
            if (sc_option_type(i) == SC_OPTION_INT) {
                if (!(fabs(v) < 9e18))
                    continue;
                st = sc_params_set_int(params, name, (int64_t)v);
            } else if (sc_option_type(i) == SC_OPTION_DOUBLE) {
                st = sc_params_set_double(params, name, v);
            } else {
                continue;
            }
            CHECK(st == SC_STATUS_OK || st == SC_STATUS_INVALID_PARAMETER, "%s = %g: %s", name,
                  v, sc_status_str(st));
            if (st == SC_STATUS_INVALID_PARAMETER)
                CHECK(strstr(sc_last_error(), name) != NULL, "%s = %g: %s", name, v,
                      sc_last_error());
            else
                CHECK(strcmp(name, "seed") == 0 || (v >= lo && v <= hi),
                      "%s = %g accepted outside [%g, %g]", name, v, lo, hi);
        }
    }
    /* Values that once aborted or hung: refused at once, naming the option. */
    CHECK_STATUS(sc_params_set_int(params, "histogram_bins", 1000000000000LL),
                 SC_STATUS_INVALID_PARAMETER);
    CHECK_STATUS(sc_params_set_int(params, "hks_times", 100000000), SC_STATUS_INVALID_PARAMETER);
    CHECK(strstr(sc_last_error(), "hks_times") != NULL, "%s", sc_last_error());
    CHECK_STATUS(sc_params_set_double(params, "sigma", 1e300), SC_STATUS_INVALID_PARAMETER);
    CHECK(strstr(sc_last_error(), "sigma") != NULL, "%s", sc_last_error());
    sc_params_free(params);
}

/* ------------------------------------------------------------------------ shape errors */

static void test_shape_errors(void) {
    /* A valid tetrahedron-like fan is too small; build 40 points on a sphere instead. */
    double xyz[3 * 40];
    uint32_t tri_bad[3] = {0, 1, 40};
    sc_shape *sentinel = (sc_shape *)(void *)&checks; /* must stay untouched on failure */
    sc_shape *shape = sentinel;
    int i;
    char path[] = "/tmp/shapecorr_c_test_XXXXXX";
    int fd;
    FILE *f;
    for (i = 0; i < 40; i++) {
        double z = -1.0 + (2.0 * i + 1.0) / 40.0, r = sqrt(1.0 - z * z), a = 2.4 * i;
        xyz[3 * i] = r * cos(a);
        xyz[3 * i + 1] = r * sin(a);
        xyz[3 * i + 2] = z;
    }

    CHECK_STATUS(sc_shape_new_mesh(xyz, 40, tri_bad, 1, NULL), SC_STATUS_NULL_ARGUMENT);
    CHECK_STATUS(sc_shape_new_mesh(NULL, 40, tri_bad, 1, &shape), SC_STATUS_NULL_ARGUMENT);
    CHECK_STATUS(sc_shape_new_mesh(xyz, 40, NULL, 1, &shape), SC_STATUS_NULL_ARGUMENT);
    CHECK_STATUS(sc_shape_new_mesh(xyz, 40, tri_bad, 1, &shape),
                 SC_STATUS_FACE_INDEX_OUT_OF_RANGE);
    CHECK(strstr(sc_last_error(), "40") != NULL, "names the index: %s", sc_last_error());
    CHECK_STATUS(sc_shape_new_mesh(NULL, 0, NULL, 0, &shape), SC_STATUS_TOO_FEW_VERTICES);
    CHECK_STATUS(sc_shape_new_point_cloud(NULL, 0, &shape), SC_STATUS_TOO_FEW_VERTICES);
    CHECK_STATUS(sc_shape_new_point_cloud(xyz, 10, &shape), SC_STATUS_TOO_FEW_VERTICES);
    CHECK_STATUS(sc_shape_new_mesh(xyz, 40, NULL, 0, &shape), SC_STATUS_ZERO_AREA);
    CHECK_STATUS(sc_shape_new_point_cloud(xyz, (size_t)-1, &shape), SC_STATUS_INVALID_ARGUMENT);
    xyz[7] = NAN;
    CHECK_STATUS(sc_shape_new_point_cloud(xyz, 40, &shape), SC_STATUS_NON_FINITE_COORDINATE);
    xyz[7] = INFINITY;
    CHECK_STATUS(sc_shape_new_point_cloud(xyz, 40, &shape), SC_STATUS_NON_FINITE_COORDINATE);
    CHECK(strstr(sc_last_error(), "vertex 2") != NULL, "names the vertex: %s", sc_last_error());
    xyz[7] = 0.5;
    CHECK_STATUS(sc_shape_new_point_cloud(xyz, 40, &shape), SC_STATUS_OK);
    CHECK(shape != sentinel && sc_shape_is_point_cloud(shape), "point cloud made");
    CHECK(sc_shape_n_vertices(shape) == 40, "40 points");
    CHECK(sc_shape_n_triangles(shape) == 0, "no triangles");
    sc_shape_free(shape);
    shape = sentinel;

    CHECK_STATUS(sc_shape_new_figure("dragon", 0, 1000, &shape), SC_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(sc_shape_new_figure("humanoid", 99, 1000, &shape),
                 SC_STATUS_INVALID_PARAMETER);
    CHECK_STATUS(sc_shape_new_figure(NULL, 0, 1000, &shape), SC_STATUS_NULL_ARGUMENT);

    /* Files: missing, malformed. */
    CHECK_STATUS(sc_shape_read("/nonexistent/shape.ply", false, &shape), SC_STATUS_FILE_ERROR);
    CHECK(strstr(sc_last_error(), "/nonexistent/shape.ply") != NULL, "names the file: %s",
          sc_last_error());
    fd = mkstemp(path);
    CHECK(fd >= 0, "temporary file");
    f = fdopen(fd, "w");
    fputs("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1 2\n", f);
    fclose(f);
    CHECK_STATUS(sc_shape_read(path, false, &shape), SC_STATUS_FILE_ERROR);
    remove(path);
    CHECK_STATUS(sc_shape_read(NULL, false, &shape), SC_STATUS_NULL_ARGUMENT);
    CHECK(shape == sentinel, "no output written by failed calls");

    CHECK(sc_shape_n_vertices(NULL) == 0, "NULL shape has no vertices");
    CHECK(sc_shape_warnings(NULL, NULL, 0) == 0, "NULL shape has no warnings");
    sc_shape_free(NULL);
}

/* A triangle soup (every face with its own corners, as unwelded exports write it) is
 * welded by default and kept as given with SC_REPAIR_NONE; every vertex keeps its index. */
static void test_repairs(void) {
    sc_shape *figure_shape = figure("humanoid", 0);
    size_t n = sc_shape_n_vertices(figure_shape), m = sc_shape_n_triangles(figure_shape), i;
    double *xyz = malloc(3 * n * sizeof *xyz), *soup = malloc(9 * m * sizeof *soup);
    uint32_t *triangles = malloc(3 * m * sizeof *triangles);
    uint32_t *soup_triangles = malloc(3 * m * sizeof *soup_triangles);
    char warnings[4096];
    sc_shape *welded = NULL, *as_given = NULL, *bad = NULL;
    CHECK(xyz && soup && triangles && soup_triangles, "allocation");
    CHECK_STATUS(sc_shape_vertices(figure_shape, xyz, 3 * n), SC_STATUS_OK);
    CHECK_STATUS(sc_shape_triangles(figure_shape, triangles, 3 * m), SC_STATUS_OK);
    for (i = 0; i < 3 * m; i++) {
        memcpy(&soup[3 * i], &xyz[3 * triangles[i]], 3 * sizeof *soup);
        soup_triangles[i] = (uint32_t)i;
    }
    CHECK_STATUS(sc_shape_new_mesh(soup, 3 * m, soup_triangles, m, &welded), SC_STATUS_OK);
    CHECK(sc_shape_n_vertices(welded) == 3 * m, "every input vertex kept its index");
    sc_shape_warnings(welded, warnings, sizeof warnings);
    CHECK(strstr(warnings, "welded") != NULL, "the weld is reported: %s", warnings);
    CHECK(strstr(warnings, "disconnected") == NULL, "one piece after welding: %s", warnings);
    CHECK(sc_shape_repairs(welded, warnings, sizeof warnings) > 0, "a repair was made");
    CHECK(strstr(warnings, "welded") != NULL, "the weld is a repair: %s", warnings);
    CHECK_STATUS(sc_shape_new_mesh_repaired(soup, 3 * m, soup_triangles, m, SC_REPAIR_NONE,
                                            &as_given),
                 SC_STATUS_OK);
    sc_shape_warnings(as_given, warnings, sizeof warnings);
    CHECK(strstr(warnings, "welded") == NULL, "no weld asked for: %s", warnings);
    CHECK(strstr(warnings, "disconnected") != NULL, "the soup stays in pieces: %s", warnings);
    CHECK(sc_shape_repairs(as_given, warnings, sizeof warnings) == 0, "no repair: %s", warnings);
    unsigned unknown_repair = SC_REPAIR_ALL + 1;
    CHECK_STATUS(sc_shape_new_mesh_repaired(soup, 3 * m, soup_triangles, m, unknown_repair, &bad),
                 SC_STATUS_INVALID_ARGUMENT);
    CHECK(bad == NULL, "no shape from unknown repair flags");
    CHECK_STATUS(sc_shape_new_point_cloud_repaired(xyz, n, SC_REPAIR_ALL, &bad), SC_STATUS_OK);
    sc_shape_free(bad);
    CHECK_STATUS(sc_shape_read_repaired("/nonexistent/shape.ply", false, SC_REPAIR_NONE, &bad),
                 SC_STATUS_FILE_ERROR);
    sc_shape_free(welded);
    sc_shape_free(as_given);
    sc_shape_free(figure_shape);
    free(xyz);
    free(soup);
    free(triangles);
    free(soup_triangles);
}

/* ----------------------------------------------------------------------- life cycle */

struct progress_log {
    int calls;
    uint32_t last_stage;
    int bad;
    int cancel_at_stage; /* 0: never cancel */
    double cancelled_at;
};

static bool record_progress(void *userdata, uint32_t stage, float fraction) {
    struct progress_log *log = (struct progress_log *)userdata;
    log->calls++;
    /* SC_STAGE_PROXY too: quick sizes (700 vertices) run on refined copies. */
    if (stage < SC_STAGE_LAPLACIAN || stage > SC_STAGE_PROXY || !(fraction >= 0.0f) ||
        !(fraction <= 1.0f))
        log->bad++;
    log->last_stage = stage;
    if (log->cancel_at_stage != 0 && stage == (uint32_t)log->cancel_at_stage) {
        if (log->cancelled_at == 0.0)
            log->cancelled_at = now_seconds();
        return false;
    }
    return true;
}

/* Fraction of vertices whose regions on A and B (same vertex order) are matched. */
static double region_accuracy(const sc_correspondence *c, uint32_t kind) {
    size_t n = sc_correspondence_n_vertices(c, SC_SIDE_A);
    size_t n_matches = sc_correspondence_n_matches(c, kind);
    size_t na = sc_correspondence_n_regions(c, SC_SIDE_A);
    size_t nb = sc_correspondence_n_regions(c, SC_SIDE_B);
    uint32_t *ra = malloc(n * sizeof *ra), *rb = malloc(n * sizeof *rb);
    uint32_t *pairs = malloc((2 * n_matches + 1) * sizeof *pairs);
    unsigned char *matched = calloc(na * nb, 1);
    size_t i, good = 0;
    CHECK_STATUS(sc_correspondence_regions(c, SC_SIDE_A, ra, n), SC_STATUS_OK);
    CHECK_STATUS(sc_correspondence_regions(c, SC_SIDE_B, rb, n), SC_STATUS_OK);
    CHECK_STATUS(sc_correspondence_matches(c, kind, pairs, 2 * n_matches), SC_STATUS_OK);
    for (i = 0; i < n_matches; i++) {
        CHECK(pairs[2 * i] < na && pairs[2 * i + 1] < nb, "match %zu in range", i);
        if (pairs[2 * i] < na && pairs[2 * i + 1] < nb)
            matched[pairs[2 * i] * nb + pairs[2 * i + 1]] = 1;
    }
    for (i = 0; i < n; i++) {
        CHECK(ra[i] < na && rb[i] < nb, "vertex %zu regions in range", i);
        if (ra[i] < na && rb[i] < nb && matched[ra[i] * nb + rb[i]])
            good++;
    }
    free(ra);
    free(rb);
    free(pairs);
    free(matched);
    return (double)good / (double)n;
}

/* A confidence is in [0, 1] or NaN (none); the warning is NULL or a non-empty sentence, and
 * it is there exactly when the confidence is below SC_CONFIDENCE_DOUBTFUL_BELOW. */
static void check_confidence(const char *what, double confidence, const char *warning) {
    bool doubtful = !isnan(confidence) && confidence < SC_CONFIDENCE_DOUBTFUL_BELOW;
    CHECK(isnan(confidence) || (confidence >= 0.0 && confidence <= 1.0), "%s: confidence %g",
          what, confidence);
    CHECK(warning == NULL || strlen(warning) > 0, "%s: empty warning", what);
    CHECK((warning != NULL) == doubtful, "%s: confidence %g, warning %s", what, confidence,
          warning != NULL ? warning : "(NULL)");
    printf("%s: confidence %g%s%s\n", what, confidence, warning != NULL ? "; " : "",
           warning != NULL ? warning : "");
}

/* What the pipeline ran on for one side of `c` whose input has `n` vertices: the input
 * itself from 2,000 vertices (option `refine_below`), else a refined copy with more
 * vertices, never smoothed (a generated figure has no noise); the bad side and NULL
 * arguments fail and write nothing. */
static void check_working(const sc_correspondence *c, uint32_t side, size_t n) {
    uint32_t kind = 99;
    size_t vertices = 0;
    bool smoothed = true;
    CHECK_STATUS(sc_correspondence_working(c, side, &kind, &vertices, &smoothed), SC_STATUS_OK);
    CHECK(!smoothed, "side %u: a clean figure is not smoothed", side);
    CHECK_STATUS(sc_correspondence_working(c, side, &kind, &vertices, NULL), SC_STATUS_OK);
    if (n >= 2000)
        CHECK(kind == SC_WORKING_INPUT && vertices == n, "side %u of %zu vertices: kind %u, %zu",
              side, n, kind, vertices);
    else
        CHECK(kind == SC_WORKING_REFINED && vertices > n,
              "side %u of %zu vertices: kind %u, %zu", side, n, kind, vertices);
    kind = 99;
    vertices = 0;
    CHECK_STATUS(sc_correspondence_working(c, 2, &kind, &vertices, &smoothed),
                 SC_STATUS_INVALID_ARGUMENT);
    CHECK(strstr(sc_last_error(), "side") != NULL, "message: %s", sc_last_error());
    CHECK_STATUS(sc_correspondence_working(c, side, NULL, &vertices, &smoothed),
                 SC_STATUS_NULL_ARGUMENT);
    CHECK_STATUS(sc_correspondence_working(c, side, &kind, NULL, &smoothed),
                 SC_STATUS_NULL_ARGUMENT);
    CHECK_STATUS(sc_correspondence_working(NULL, side, &kind, &vertices, &smoothed),
                 SC_STATUS_NULL_ARGUMENT);
    CHECK(kind == 99 && vertices == 0, "nothing written on failure");
    /* A generated figure in one piece has no object touching it to leave out. */
    size_t pieces = 99, left_out = 99;
    CHECK_STATUS(sc_correspondence_objects_left_out(c, side, &pieces, &left_out), SC_STATUS_OK);
    CHECK(pieces == 0 && left_out == 0, "side %u: %zu pieces, %zu vertices left out", side,
          pieces, left_out);
    CHECK_STATUS(sc_correspondence_objects_left_out(c, side, &pieces, NULL), SC_STATUS_OK);
    pieces = 99;
    CHECK_STATUS(sc_correspondence_objects_left_out(c, 2, &pieces, &left_out),
                 SC_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(sc_correspondence_objects_left_out(c, side, NULL, &left_out),
                 SC_STATUS_NULL_ARGUMENT);
    CHECK_STATUS(sc_correspondence_objects_left_out(NULL, side, &pieces, &left_out),
                 SC_STATUS_NULL_ARGUMENT);
    CHECK(pieces == 99, "nothing written on failure");
    /* Nor any the time limit kept the job from trying without. */
    CHECK_STATUS(sc_correspondence_objects_not_tried(c, side, &pieces), SC_STATUS_OK);
    CHECK(pieces == 0, "side %u: %zu pieces not tried", side, pieces);
    pieces = 99;
    CHECK_STATUS(sc_correspondence_objects_not_tried(c, 2, &pieces), SC_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(sc_correspondence_objects_not_tried(c, side, NULL), SC_STATUS_NULL_ARGUMENT);
    CHECK(pieces == 99, "nothing written on failure");
}

/* A low-poly figure (600 vertices) runs on a refined copy, the plain one beside it on
 * itself. */
static void test_working(void) {
    sc_shape *a = NULL, *b = figure("star4", 2);
    sc_params *params = NULL;
    sc_correspondence *c = NULL;
    CHECK_STATUS(sc_shape_new_figure("star4", 0, 600, &a), SC_STATUS_OK);
    if (a == NULL || b == NULL)
        goto done;
    CHECK(sc_shape_n_vertices(a) < 2000, "a low-poly figure: %zu", sc_shape_n_vertices(a));
    CHECK_STATUS(sc_params_new(&params), SC_STATUS_OK);
    CHECK_STATUS(sc_params_set_bool(params, "verify_hypotheses", false), SC_STATUS_OK);
    CHECK_STATUS(sc_match(a, b, params, NULL, NULL, &c), SC_STATUS_OK);
    if (c != NULL) {
        check_working(c, SC_SIDE_A, sc_shape_n_vertices(a));
        check_working(c, SC_SIDE_B, sc_shape_n_vertices(b));
    }
done:
    sc_correspondence_free(c);
    sc_params_free(params);
    sc_shape_free(a);
    sc_shape_free(b);
}

static void test_life_cycle(void) {
    sc_shape *a = figure("humanoid", 0), *b_mesh = figure("humanoid", 3), *b = NULL;
    sc_params *params = NULL;
    sc_correspondence *c = NULL;
    struct progress_log log = {0, 0, 0, 0, 0.0};
    size_t nv, nt, na, nb, dim, ne, i;
    double *xyz_d, sym, one, area, seconds, total;
    float *xyz_f;
    uint32_t *tri, *regions, *edges;
    uint8_t *rgba, *rgba_b;
    double *areas, *descriptors;
    if (a == NULL || b_mesh == NULL)
        return;

    /* Copy B out and back in through the float path: the same shape. */
    nv = sc_shape_n_vertices(b_mesh);
    nt = sc_shape_n_triangles(b_mesh);
    xyz_d = malloc(3 * nv * sizeof *xyz_d);
    xyz_f = malloc(3 * nv * sizeof *xyz_f);
    tri = malloc(3 * nt * sizeof *tri);
    CHECK_STATUS(sc_shape_vertices(b_mesh, xyz_d, 3 * nv), SC_STATUS_OK);
    CHECK_STATUS(sc_shape_triangles(b_mesh, tri, 3 * nt), SC_STATUS_OK);
    CHECK_STATUS(sc_shape_vertices(b_mesh, xyz_d, 3 * nv - 1), SC_STATUS_BUFFER_TOO_SMALL);
    for (i = 0; i < 3 * nv; i++)
        xyz_f[i] = (float)xyz_d[i];
    CHECK_STATUS(sc_shape_new_mesh_f32(xyz_f, nv, tri, nt, &b), SC_STATUS_OK);
    CHECK(sc_shape_n_vertices(b) == nv && sc_shape_n_triangles(b) == nt, "float copy");
    CHECK(!sc_shape_is_point_cloud(b), "a mesh");

    CHECK_STATUS(sc_params_new(&params), SC_STATUS_OK);
    CHECK_STATUS(sc_match(a, b, params, record_progress, &log, &c), SC_STATUS_OK);
    CHECK(log.calls > 5 && log.bad == 0, "%d progress calls, %d bad", log.calls, log.bad);
    CHECK(c != NULL, "result");
    if (c == NULL)
        goto done;

    CHECK(sc_correspondence_k(c) >= 5 && sc_correspondence_k(c) <= 10, "k = %u",
          sc_correspondence_k(c));
    CHECK(sc_correspondence_n_vertices(c, SC_SIDE_A) == sc_shape_n_vertices(a), "n A");
    CHECK(sc_correspondence_n_vertices(c, SC_SIDE_B) == nv, "n B");
    na = sc_correspondence_n_regions(c, SC_SIDE_A);
    nb = sc_correspondence_n_regions(c, SC_SIDE_B);
    CHECK(na >= 5 && nb >= 5, "%zu and %zu regions", na, nb);
    sym = region_accuracy(c, SC_MATCHES_SYMMETRIC);
    one = region_accuracy(c, SC_MATCHES_ONE_TO_ONE);
    printf("life cycle: %zu vs %zu vertices, k = %u, %zu/%zu regions, accuracy symmetric "
           "%.3f, one-to-one %.3f\n",
           sc_shape_n_vertices(a), nv, sc_correspondence_k(c), na, nb, sym, one);
    CHECK(sym >= (quick ? 0.7 : 0.9), "symmetric accuracy %.3f", sym);
    check_confidence("life cycle", sc_correspondence_confidence(c), sc_correspondence_warning(c));
    check_working(c, SC_SIDE_A, sc_shape_n_vertices(a));
    check_working(c, SC_SIDE_B, nv);
    CHECK(sc_correspondence_warning(c) == sc_correspondence_warning(c),
          "the warning is the handle's own string");
    CHECK(sc_correspondence_n_matches(c, SC_MATCHES_ONE_TO_ONE) <=
              sc_correspondence_n_matches(c, SC_MATCHES_SYMMETRIC),
          "one-to-one is a subset");

    /* Colours: same length rules; a vertex pair in one-to-one matched regions shares colour. */
    rgba = malloc(4 * nv);
    rgba_b = malloc(4 * nv);
    regions = malloc(nv * sizeof *regions);
    CHECK(sc_correspondence_n_vertices(c, SC_SIDE_A) == nv, "poses share the vertex order");
    CHECK_STATUS(sc_correspondence_colors(c, SC_SIDE_A, SC_MATCHES_ONE_TO_ONE, rgba, 4 * nv - 1),
                 SC_STATUS_BUFFER_TOO_SMALL);
    CHECK_STATUS(sc_correspondence_colors(c, SC_SIDE_A, SC_MATCHES_ONE_TO_ONE, rgba, 4 * nv),
                 SC_STATUS_OK);
    CHECK_STATUS(sc_correspondence_colors(c, SC_SIDE_B, SC_MATCHES_ONE_TO_ONE, rgba_b, 4 * nv),
                 SC_STATUS_OK);
    {
        /* Where the vertex's regions are matched one-to-one, both shapes show one colour. */
        size_t same = 0;
        for (i = 0; i < nv; i++)
            same += memcmp(rgba + 4 * i, rgba_b + 4 * i, 4) == 0;
        CHECK((double)same / (double)nv >= one - 1e-9, "colour agreement %.3f vs one-to-one %.3f",
              (double)same / (double)nv, one);
    }
    for (i = 0; i < nv; i++)
        CHECK(rgba_b[4 * i + 3] == 255, "alpha");
    CHECK_STATUS(sc_correspondence_colors(c, 2, SC_MATCHES_ONE_TO_ONE, rgba_b, 4 * nv),
                 SC_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(sc_correspondence_colors(c, SC_SIDE_B, 7, rgba_b, 4 * nv),
                 SC_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(sc_correspondence_colors(c, SC_SIDE_B, SC_MATCHES_SYMMETRIC, NULL, 4 * nv),
                 SC_STATUS_NULL_ARGUMENT);

    /* Buffer too small leaves the buffer untouched. */
    memset(regions, 0xAB, nv * sizeof *regions);
    CHECK_STATUS(sc_correspondence_regions(c, SC_SIDE_B, regions, nv - 1),
                 SC_STATUS_BUFFER_TOO_SMALL);
    CHECK(regions[0] == 0xABABABABu, "untouched on failure");
    CHECK_STATUS(sc_correspondence_regions(NULL, SC_SIDE_B, regions, nv), SC_STATUS_NULL_ARGUMENT);
    CHECK(sc_correspondence_n_regions(c, 5) == 0, "bad side counts 0");

    /* Shape graphs: areas sum to 1, descriptors of the HKS length, edges in range. */
    dim = sc_correspondence_descriptor_length(c);
    CHECK(dim == 15, "descriptor length %zu", dim);
    areas = malloc(nb * sizeof *areas);
    descriptors = malloc(nb * dim * sizeof *descriptors);
    CHECK_STATUS(sc_correspondence_region_areas(c, SC_SIDE_B, areas, nb), SC_STATUS_OK);
    area = 0.0;
    for (i = 0; i < nb; i++)
        area += areas[i];
    CHECK(fabs(area - 1.0) < 1e-9, "areas sum to %.12f", area);
    CHECK_STATUS(sc_correspondence_region_descriptors(c, SC_SIDE_B, descriptors, nb * dim),
                 SC_STATUS_OK);
    for (i = 0; i < nb * dim; i++)
        CHECK(isfinite(descriptors[i]) && descriptors[i] >= 0.0, "descriptor %zu", i);
    ne = sc_correspondence_n_edges(c, SC_SIDE_B);
    CHECK(ne >= nb - 1, "a connected graph has at least n-1 edges: %zu", ne);
    edges = malloc((2 * ne + 1) * sizeof *edges);
    CHECK_STATUS(sc_correspondence_edges(c, SC_SIDE_B, edges, 2 * ne), SC_STATUS_OK);
    for (i = 0; i < ne; i++)
        CHECK(edges[2 * i] < edges[2 * i + 1] && edges[2 * i + 1] < nb, "edge %zu", i);

    CHECK_STATUS(sc_correspondence_seconds(c, "total", &total), SC_STATUS_OK);
    CHECK_STATUS(sc_correspondence_seconds(c, "eigenbasis_a", &seconds), SC_STATUS_OK);
    CHECK(total > 0.0 && seconds > 0.0 && seconds <= total, "timings %g of %g", seconds, total);
    CHECK_STATUS(sc_correspondence_seconds(c, "lunch", &seconds), SC_STATUS_INVALID_ARGUMENT);

    free(rgba);
    free(rgba_b);
    free(regions);
    free(areas);
    free(descriptors);
    free(edges);
done:
    sc_correspondence_free(c);
    sc_correspondence_free(NULL);
    /* NULL: no confidence, no warning, as the other getters give 0. */
    CHECK(isnan(sc_correspondence_confidence(NULL)), "NULL has no confidence");
    CHECK(sc_correspondence_warning(NULL) == NULL, "NULL has no warning");
    sc_params_free(params);
    sc_shape_free(a);
    sc_shape_free(b);
    sc_shape_free(b_mesh);
    free(xyz_d);
    free(xyz_f);
    free(tri);
}

/* A mesh against a noisy point cloud made from another pose's vertices. */
static void test_point_cloud(void) {
    sc_shape *a = figure("humanoid", 0), *mesh = figure("humanoid", 2), *cloud = NULL;
    sc_correspondence *c = NULL;
    size_t n, i;
    double *xyz, acc;
    unsigned seed = 12345u;
    if (a == NULL || mesh == NULL)
        return;
    n = sc_shape_n_vertices(mesh);
    xyz = malloc(3 * n * sizeof *xyz);
    CHECK_STATUS(sc_shape_vertices(mesh, xyz, 3 * n), SC_STATUS_OK);
    for (i = 0; i < 3 * n; i++) {
        seed = seed * 1103515245u + 12345u;
        xyz[i] += 0.002 * ((double)(seed >> 16 & 0x7fff) / 32767.0 - 0.5);
    }
    CHECK_STATUS(sc_shape_new_point_cloud(xyz, n, &cloud), SC_STATUS_OK);
    CHECK_STATUS(sc_match(a, cloud, NULL, NULL, NULL, &c), SC_STATUS_OK);
    if (c != NULL) {
        acc = region_accuracy(c, SC_MATCHES_SYMMETRIC);
        printf("mesh vs point cloud: symmetric accuracy %.3f\n", acc);
        CHECK(acc >= (quick ? 0.6 : 0.8), "mesh vs cloud accuracy %.3f", acc);
    }
    sc_correspondence_free(c);
    sc_shape_free(a);
    sc_shape_free(mesh);
    sc_shape_free(cloud);
    free(xyz);
}

/* Without the verification of hypotheses (or without the one-to-one step) there is no
 * confidence: NaN, and no warning. */
static void test_unverified_has_no_confidence(void) {
    sc_shape *a = figure("star4", 0), *b = figure("star4", 2);
    sc_params *params = NULL;
    sc_correspondence *c = NULL, *other = NULL;
    bool verify = false;
    if (a == NULL || b == NULL)
        return;
    CHECK_STATUS(sc_params_new(&params), SC_STATUS_OK);
    CHECK_STATUS(sc_params_get_bool(params, "verify_hypotheses", &verify), SC_STATUS_OK);
    CHECK(verify, "verify_hypotheses is on by default");
    CHECK_STATUS(sc_params_set_bool(params, "verify_hypotheses", false), SC_STATUS_OK);
    CHECK_STATUS(sc_match(a, b, params, NULL, NULL, &c), SC_STATUS_OK);
    if (c != NULL) {
        CHECK(isnan(sc_correspondence_confidence(c)), "confidence %g without verification",
              sc_correspondence_confidence(c));
        CHECK(sc_correspondence_warning(c) == NULL, "no warning without verification");
        CHECK(sc_correspondence_hypothesis(c, SC_ANSWER_CHOSEN) == NULL, "no hypothesis");
        CHECK(sc_correspondence_decided_by(c) == NULL, "nothing decided");
        CHECK(isnan(sc_correspondence_turn_degrees(c, SC_ANSWER_CHOSEN)), "no turn");
        CHECK_STATUS(sc_correspondence_other_answer(c, &other), SC_STATUS_INVALID_ARGUMENT);
        CHECK(strstr(sc_last_error(), "no other answer") != NULL, "message: %s",
              sc_last_error());
        CHECK(other == NULL, "nothing written on failure");
    }
    sc_correspondence_free(c);
    sc_params_free(params);
    sc_shape_free(a);
    sc_shape_free(b);
}

static void test_match_errors(void) {
    sc_shape *a = figure("star5", 0);
    sc_params *params = NULL;
    sc_correspondence *sentinel = (sc_correspondence *)(void *)&checks, *c = sentinel;
    double t0;
    CHECK_STATUS(sc_match(a, NULL, NULL, NULL, NULL, &c), SC_STATUS_NULL_ARGUMENT);
    CHECK_STATUS(sc_match(NULL, a, NULL, NULL, NULL, &c), SC_STATUS_NULL_ARGUMENT);
    CHECK_STATUS(sc_match(a, a, NULL, NULL, NULL, NULL), SC_STATUS_NULL_ARGUMENT);
    CHECK_STATUS(sc_params_new(&params), SC_STATUS_OK);
    CHECK_STATUS(sc_params_set_int(params, "k_min", 8), SC_STATUS_OK);
    CHECK_STATUS(sc_params_set_int(params, "k_max", 5), SC_STATUS_OK);
    t0 = now_seconds();
    CHECK_STATUS(sc_match(a, a, params, NULL, NULL, &c), SC_STATUS_INVALID_PARAMETER);
    CHECK(now_seconds() - t0 < 0.5, "parameters are checked before any work");
    CHECK(strstr(sc_last_error(), "k_min") != NULL, "message: %s", sc_last_error());
    CHECK(c == sentinel, "no output on failure");
    sc_params_free(params);
    sc_shape_free(a);
}

/* A job too big for its limits is SC_STATUS_RESOURCE_LIMIT, not INVALID_PARAMETER: refused at
   once by the memory ceiling (every kind of job) and by max_vertices, with a message naming
   the limit and what to do; the same options out of their range stay INVALID_PARAMETER. */
static void test_resource_limits(void) {
    sc_shape *a = figure("star5", 0);
    sc_params *params = NULL;
    sc_correspondence *c_sentinel = (sc_correspondence *)(void *)&checks, *c = c_sentinel;
    sc_symmetry *s_sentinel = (sc_symmetry *)(void *)&checks, *s = s_sentinel;
    sc_pointwise *p_sentinel = (sc_pointwise *)(void *)&checks, *p = p_sentinel;
    double t0;
    CHECK_STATUS(sc_params_new(&params), SC_STATUS_OK);
    CHECK_STATUS(sc_params_set_int(params, "memory_limit_mib", -1), SC_STATUS_INVALID_PARAMETER);
    CHECK_STATUS(sc_params_set_int(params, "memory_limit_mib", 1), SC_STATUS_OK);
    t0 = now_seconds();
    CHECK_STATUS(sc_match(a, a, params, NULL, NULL, &c), SC_STATUS_RESOURCE_LIMIT);
    CHECK(strstr(sc_last_error(), "memory_limit_mib") != NULL, "message: %s", sc_last_error());
    CHECK(strstr(sc_last_error(), "needs about") != NULL, "message: %s", sc_last_error());
    CHECK(strstr(sc_last_error(), "raise memory_limit_mib") != NULL, "message: %s",
          sc_last_error());
    CHECK_STATUS(sc_symmetry_detect(a, params, NULL, NULL, &s), SC_STATUS_RESOURCE_LIMIT);
    CHECK_STATUS(sc_pointwise_map(a, a, params, NULL, NULL, &p), SC_STATUS_RESOURCE_LIMIT);
    CHECK(now_seconds() - t0 < 0.5, "refused before any work");
    CHECK(c == c_sentinel && s == s_sentinel && p == p_sentinel, "no output on failure");
    sc_params_free(params);

    CHECK_STATUS(sc_params_new(&params), SC_STATUS_OK);
    CHECK_STATUS(sc_params_set_int(params, "max_vertices", 1), SC_STATUS_INVALID_PARAMETER);
    CHECK_STATUS(sc_params_set_int(params, "max_vertices", 100), SC_STATUS_OK);
    CHECK_STATUS(sc_match(a, a, params, NULL, NULL, &c), SC_STATUS_RESOURCE_LIMIT);
    CHECK(strstr(sc_last_error(), "max_vertices") != NULL, "message: %s", sc_last_error());
    CHECK(c == c_sentinel, "no output on failure");
    sc_params_free(params);
    sc_shape_free(a);
}

static void test_cancellation(void) {
    sc_shape *a = figure("humanoid", 0), *b = figure("humanoid", 1);
    sc_correspondence *sentinel = (sc_correspondence *)(void *)&checks, *c = sentinel;
    sc_symmetry *s_sentinel = (sc_symmetry *)(void *)&checks, *s = s_sentinel;
    uint32_t stage;
    for (stage = SC_STAGE_EIGENBASIS; stage <= SC_STAGE_SYMMETRY_BREAKING; stage++) {
        struct progress_log log = {0, 0, 0, 0, 0.0};
        double latency;
        if (stage == SC_STAGE_DESCRIPTORS)
            continue; /* too short to be interesting; cancelled like the others */
        log.cancel_at_stage = (int)stage;
        CHECK_STATUS(sc_match(a, b, NULL, record_progress, &log, &c), SC_STATUS_CANCELLED);
        latency = now_seconds() - log.cancelled_at;
        CHECK(log.cancelled_at > 0.0, "stage %u was reported", stage);
        CHECK(latency < 0.5, "stopped %.3f s after the cancel at stage %u", latency, stage);
        CHECK(c == sentinel, "no output when cancelled");
    }
    {
        struct progress_log log = {0, 0, 0, SC_STAGE_SEGMENTATION, 0.0};
        CHECK_STATUS(sc_symmetry_detect(a, NULL, record_progress, &log, &s),
                     SC_STATUS_CANCELLED);
        CHECK(s == s_sentinel, "no symmetry output when cancelled");
    }
    sc_shape_free(a);
    sc_shape_free(b);
}

static void test_symmetry(void) {
    sc_shape *star = figure("star5", 0);
    sc_symmetry *s = NULL;
    size_t nr, ng, nv, i, largest = 0;
    uint32_t *groups, *sizes;
    uint8_t *rgba;
    CHECK_STATUS(sc_symmetry_detect(star, NULL, NULL, NULL, &s), SC_STATUS_OK);
    if (s == NULL) {
        sc_shape_free(star);
        return;
    }
    nr = sc_symmetry_n_regions(s);
    ng = sc_symmetry_n_groups(s);
    nv = sc_symmetry_n_vertices(s);
    CHECK(nv == sc_shape_n_vertices(star), "vertices");
    CHECK(ng >= 1 && ng < nr, "%zu groups of %zu regions", ng, nr);
    groups = malloc(nr * sizeof *groups);
    sizes = calloc(ng, sizeof *sizes);
    CHECK_STATUS(sc_symmetry_region_groups(s, groups, nr), SC_STATUS_OK);
    for (i = 0; i < nr; i++) {
        CHECK(groups[i] < ng, "group in range");
        if (groups[i] < ng && ++sizes[groups[i]] > largest)
            largest = sizes[groups[i]];
    }
    printf("star5 symmetry: %zu regions in %zu groups, largest group %zu\n", nr, ng, largest);
    CHECK(largest == 5, "the five limbs form a group: largest group %zu", largest);
    rgba = malloc(4 * nv);
    CHECK_STATUS(sc_symmetry_colors(s, rgba, 4 * nv), SC_STATUS_OK);
    CHECK_STATUS(sc_symmetry_colors(s, rgba, 4 * nv - 4), SC_STATUS_BUFFER_TOO_SMALL);
    free(groups);
    free(sizes);
    free(rgba);
    sc_symmetry_free(s);
    sc_symmetry_free(NULL);
    sc_shape_free(star);
}

/* ----------------------------------------------------------------- pointwise maps */

/* Eigenpairs (and ZoomOut's final size) of the pointwise tests: the default, or in quick
 * mode the region matching's own 50, so that valgrind does not wait on a larger basis. */
static int64_t p2p_eigenpairs(void) { return quick ? 50 : 100; }

static sc_params *pointwise_params(void) {
    sc_params *params = NULL;
    CHECK_STATUS(sc_params_new(&params), SC_STATUS_OK);
    if (quick) {
        CHECK_STATUS(sc_params_set_int(params, "p2p_eigenpairs", p2p_eigenpairs()), SC_STATUS_OK);
        CHECK_STATUS(sc_params_set_int(params, "p2p_fmap_size", 20), SC_STATUS_OK);
        CHECK_STATUS(sc_params_set_int(params, "p2p_zoomout_end", p2p_eigenpairs()),
                     SC_STATUS_OK);
    }
    return params;
}

static void test_pointwise_options(void) {
    sc_params *params = NULL;
    int64_t v = -1;
    double w = -1.0;
    bool flag = false;
    size_t i, n_p2p = 0;
    for (i = 0; i < sc_option_count(); i++)
        n_p2p += strncmp(sc_option_name(i), "p2p_", 4) == 0;
    CHECK(n_p2p >= 10, "%zu pointwise options", n_p2p);
    CHECK_STATUS(sc_params_new(&params), SC_STATUS_OK);
    /* Defaults are PointwiseParams::default()'s. */
    CHECK_STATUS(sc_params_get_int(params, "p2p_eigenpairs", &v), SC_STATUS_OK);
    CHECK(v == 100, "p2p_eigenpairs %lld", (long long)v);
    CHECK_STATUS(sc_params_get_int(params, "p2p_fmap_size", &v), SC_STATUS_OK);
    CHECK(v == 40, "p2p_fmap_size %lld", (long long)v);
    CHECK_STATUS(sc_params_get_int(params, "p2p_regions", &v), SC_STATUS_OK);
    CHECK(v == SC_P2P_REGIONS_ONE_TO_ONE, "p2p_regions %lld", (long long)v);
    CHECK_STATUS(sc_params_get_int(params, "p2p_refinement", &v), SC_STATUS_OK);
    CHECK(v == SC_P2P_REFINEMENT_ZOOMOUT, "p2p_refinement %lld", (long long)v);
    CHECK_STATUS(sc_params_get_int(params, "p2p_zoomout_end", &v), SC_STATUS_OK);
    CHECK(v == 100, "p2p_zoomout_end %lld", (long long)v);
    CHECK_STATUS(sc_params_get_double(params, "p2p_laplacian_weight", &w), SC_STATUS_OK);
    CHECK(w == 1.0, "p2p_laplacian_weight %g", w);
    CHECK_STATUS(sc_params_get_bool(params, "p2p_region_distances", &flag), SC_STATUS_OK);
    CHECK(flag, "region distances on by default");
    CHECK_STATUS(sc_params_get_bool(params, "p2p_wks", &flag), SC_STATUS_OK);
    CHECK(!flag, "WKS off by default");

    /* The choices' names, by value, as the command line takes them. */
    for (i = 0; i < sc_option_count(); i++) {
        const char *name = sc_option_name(i);
        if (strcmp(name, "p2p_refinement") == 0) {
            CHECK(strcmp(sc_option_choice(i, SC_P2P_REFINEMENT_NONE), "none") == 0, "none");
            CHECK(strcmp(sc_option_choice(i, SC_P2P_REFINEMENT_ZOOMOUT), "zoomout") == 0,
                  "zoomout");
            CHECK(strcmp(sc_option_choice(i, SC_P2P_REFINEMENT_ICP), "icp") == 0, "icp");
            CHECK(sc_option_choice(i, 3) == NULL, "past the last choice");
        } else if (strcmp(name, "p2p_regions") == 0) {
            CHECK(strcmp(sc_option_choice(i, SC_P2P_REGIONS_SYMMETRIC), "symmetric") == 0,
                  "symmetric");
        } else if (strcmp(name, "placement") == 0) {
            CHECK(strcmp(sc_option_choice(i, SC_PLACEMENT_AUTO), "auto") == 0, "auto");
            CHECK(strcmp(sc_option_choice(i, SC_PLACEMENT_IGNORE), "ignore") == 0, "ignore");
            CHECK(strcmp(sc_option_choice(i, SC_PLACEMENT_TRUST), "trust") == 0, "trust");
            CHECK(sc_option_choice(i, 3) == NULL, "past the last choice");
        } else if (strcmp(name, "partial") == 0) {
            CHECK(strcmp(sc_option_choice(i, SC_PARTIAL_AUTO), "auto") == 0, "auto");
            CHECK(strcmp(sc_option_choice(i, SC_PARTIAL_OFF), "off") == 0, "off");
            CHECK(strcmp(sc_option_choice(i, SC_PARTIAL_B_IN_A), "b_in_a") == 0, "b_in_a");
            CHECK(strcmp(sc_option_choice(i, SC_PARTIAL_A_IN_B), "a_in_b") == 0, "a_in_b");
            CHECK(sc_option_choice(i, 4) == NULL, "past the last choice");
        } else {
            CHECK(sc_option_choice(i, 0) == NULL, "%s is not a choice", name);
        }
    }
    CHECK(sc_option_choice(sc_option_count(), 0) == NULL, "past the last option");

    /* Bad values: choices out of their list, wrong types, non-finite; nothing changes. */
    CHECK_STATUS(sc_params_set_int(params, "p2p_regions", 3), SC_STATUS_INVALID_PARAMETER);
    CHECK(strstr(sc_last_error(), "p2p_regions") != NULL, "message: %s", sc_last_error());
    CHECK_STATUS(sc_params_set_int(params, "p2p_regions", -1), SC_STATUS_INVALID_PARAMETER);
    CHECK_STATUS(sc_params_set_int(params, "p2p_refinement", 7), SC_STATUS_INVALID_PARAMETER);
    CHECK_STATUS(sc_params_set_int(params, "p2p_fmap_size", -5), SC_STATUS_INVALID_PARAMETER);
    CHECK_STATUS(sc_params_set_double(params, "p2p_fmap_size", 30.0),
                 SC_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(sc_params_set_double(params, "p2p_laplacian_weight", NAN),
                 SC_STATUS_INVALID_PARAMETER);
    CHECK_STATUS(sc_params_set_int(params, "p2p_wks", 1), SC_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(sc_params_set_int(params, "p2p_nonsense", 1), SC_STATUS_UNKNOWN_OPTION);
    CHECK_STATUS(sc_params_get_int(params, "p2p_regions", &v), SC_STATUS_OK);
    CHECK(v == SC_P2P_REGIONS_ONE_TO_ONE, "unchanged by failed calls: %lld", (long long)v);
    CHECK_STATUS(sc_params_get_int(params, "p2p_fmap_size", &v), SC_STATUS_OK);
    CHECK(v == 40, "unchanged by failed calls: %lld", (long long)v);

    /* Settings of a refinement survive choosing another one (any order of setters). */
    CHECK_STATUS(sc_params_set_int(params, "p2p_refinement", SC_P2P_REFINEMENT_ICP),
                 SC_STATUS_OK);
    CHECK_STATUS(sc_params_set_int(params, "p2p_zoomout_end", 60), SC_STATUS_OK);
    CHECK_STATUS(sc_params_set_int(params, "p2p_refinement", SC_P2P_REFINEMENT_ZOOMOUT),
                 SC_STATUS_OK);
    CHECK_STATUS(sc_params_get_int(params, "p2p_zoomout_end", &v), SC_STATUS_OK);
    CHECK(v == 60, "p2p_zoomout_end kept: %lld", (long long)v);
    sc_params_free(params);
}

/* Parameters checked by sc_pointwise_map before any work: each fails at once. */
static void test_pointwise_errors(void) {
    sc_shape *a = figure("star5", 0);
    sc_params *params = NULL;
    sc_pointwise *sentinel = (sc_pointwise *)(void *)&checks, *p = sentinel;
    double t0;
    struct {
        const char *name;
        int64_t value;
    } bad[] = {
        {"p2p_fmap_size", 120},   /* above p2p_eigenpairs (100) */
        {"p2p_zoomout_end", 150}, /* above p2p_eigenpairs */
        {"p2p_regions", SC_P2P_REGIONS_NONE}, /* and no WKS: nothing constrains the map */
        {"k_max", 3},                         /* below k_min */
    };
    size_t i;
    CHECK_STATUS(sc_pointwise_map(NULL, a, NULL, NULL, NULL, &p), SC_STATUS_NULL_ARGUMENT);
    CHECK_STATUS(sc_pointwise_map(a, NULL, NULL, NULL, NULL, &p), SC_STATUS_NULL_ARGUMENT);
    CHECK_STATUS(sc_pointwise_map(a, a, NULL, NULL, NULL, NULL), SC_STATUS_NULL_ARGUMENT);
    CHECK(strstr(sc_last_error(), "out_pointwise") != NULL, "message: %s", sc_last_error());
    /* A value out of its own range is refused when set (docs/decisions.md, "Option ranges"). */
    CHECK_STATUS(sc_params_new(&params), SC_STATUS_OK);
    CHECK_STATUS(sc_params_set_int(params, "p2p_zoomout_step", 0), SC_STATUS_INVALID_PARAMETER);
    sc_params_free(params);
    params = NULL;
    for (i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        CHECK_STATUS(sc_params_new(&params), SC_STATUS_OK);
        CHECK_STATUS(sc_params_set_int(params, bad[i].name, bad[i].value), SC_STATUS_OK);
        t0 = now_seconds();
        CHECK_STATUS(sc_pointwise_map(a, a, params, NULL, NULL, &p), SC_STATUS_INVALID_PARAMETER);
        CHECK(now_seconds() - t0 < 0.5, "%s checked before any work", bad[i].name);
        CHECK(p == sentinel, "no output on failure (%s)", bad[i].name);
        sc_params_free(params);
        params = NULL;
    }
    /* Accessors on NULL. */
    CHECK(sc_pointwise_n_vertices(NULL, SC_SIDE_B) == 0, "NULL has no vertices");
    CHECK(sc_pointwise_fmap_rows(NULL) == 0 && sc_pointwise_fmap_cols(NULL) == 0, "NULL fmap");
    CHECK_STATUS(sc_pointwise_map_b_to_a(NULL, NULL, 0), SC_STATUS_NULL_ARGUMENT);
    CHECK_STATUS(sc_pointwise_fmap(NULL, NULL, 0), SC_STATUS_NULL_ARGUMENT);
    CHECK_STATUS(sc_pointwise_regions(NULL, NULL), SC_STATUS_NULL_ARGUMENT);
    CHECK_STATUS(sc_pointwise_seconds(NULL, "total", &t0), SC_STATUS_NULL_ARGUMENT);
    CHECK(isnan(sc_pointwise_confidence(NULL)), "NULL has no confidence");
    CHECK(sc_pointwise_warning(NULL) == NULL, "NULL has no warning");
    sc_pointwise_free(NULL);
    sc_shape_free(a);
}

/* B is A with its vertices permuted (vertex j of B is vertex perm[j] of A) and its
 * triangles re-indexed: an isometric copy, so the map from B to A composed with the
 * permutation is the identity. */
static void test_pointwise_permuted_copy(void) {
    sc_shape *a = figure("humanoid", 3), *b = NULL;
    sc_params *params = NULL;
    sc_pointwise *p = NULL;
    sc_correspondence *regions = NULL;
    struct progress_log log = {0, 0, 0, 0, 0.0};
    size_t n, nt, i, exact = 0, rows, cols;
    size_t *perm, *inverse;
    uint32_t *tri_a, *tri_b, *map;
    double *xyz_a, *xyz_b, *fmap, lo[3], hi[3], diagonal = 0.0, error = 0.0, seconds, total;
    unsigned seed = 2024u;
    int k;
    if (a == NULL)
        return;
    n = sc_shape_n_vertices(a);
    nt = sc_shape_n_triangles(a);
    perm = malloc(n * sizeof *perm);
    inverse = malloc(n * sizeof *inverse);
    xyz_a = malloc(3 * n * sizeof *xyz_a);
    xyz_b = malloc(3 * n * sizeof *xyz_b);
    tri_a = malloc(3 * nt * sizeof *tri_a);
    tri_b = malloc(3 * nt * sizeof *tri_b);
    map = malloc(n * sizeof *map);
    CHECK_STATUS(sc_shape_vertices(a, xyz_a, 3 * n), SC_STATUS_OK);
    CHECK_STATUS(sc_shape_triangles(a, tri_a, 3 * nt), SC_STATUS_OK);
    for (i = 0; i < n; i++)
        perm[i] = i;
    for (i = n - 1; i > 0; i--) { /* Fisher-Yates with a fixed LCG */
        size_t j, t;
        seed = seed * 1103515245u + 12345u;
        j = (size_t)(seed >> 8) % (i + 1);
        t = perm[i];
        perm[i] = perm[j];
        perm[j] = t;
    }
    for (i = 0; i < n; i++) {
        inverse[perm[i]] = i;
        for (k = 0; k < 3; k++)
            xyz_b[3 * i + k] = xyz_a[3 * perm[i] + k];
    }
    for (i = 0; i < 3 * nt; i++)
        tri_b[i] = (uint32_t)inverse[tri_a[i]];
    CHECK_STATUS(sc_shape_new_mesh(xyz_b, n, tri_b, nt, &b), SC_STATUS_OK);

    params = pointwise_params();
    CHECK_STATUS(sc_pointwise_map(a, b, params, record_progress, &log, &p), SC_STATUS_OK);
    CHECK(log.calls > 5 && log.bad == 0, "%d progress calls, %d bad", log.calls, log.bad);
    if (p == NULL)
        goto done;
    {
        /* The map is brought back to the input vertices last when it ran on a copy. */
        uint32_t kind = 99;
        size_t vertices = 0;
        CHECK_STATUS(sc_pointwise_working(p, SC_SIDE_A, &kind, &vertices, NULL), SC_STATUS_OK);
        CHECK(log.last_stage ==
                  (kind == SC_WORKING_INPUT ? SC_STAGE_POINTWISE_MAP : SC_STAGE_PROXY),
              "last stage %u, working kind %u", log.last_stage, kind);
    }
    CHECK(sc_pointwise_n_vertices(p, SC_SIDE_A) == n, "n A");
    CHECK(sc_pointwise_n_vertices(p, SC_SIDE_B) == n, "n B");
    CHECK(sc_pointwise_n_vertices(p, 2) == 0, "bad side counts 0");

    /* Wrong buffer sizes and NULL buffers fail and leave the buffer untouched. */
    memset(map, 0xAB, n * sizeof *map);
    CHECK_STATUS(sc_pointwise_map_b_to_a(p, map, n - 1), SC_STATUS_BUFFER_TOO_SMALL);
    CHECK_STATUS(sc_pointwise_map_b_to_a(p, map, 0), SC_STATUS_BUFFER_TOO_SMALL);
    CHECK_STATUS(sc_pointwise_map_b_to_a(p, NULL, n), SC_STATUS_NULL_ARGUMENT);
    for (i = 0; i < n; i++)
        if (map[i] != 0xABABABABu)
            break;
    CHECK(i == n, "buffer touched at %zu by a failed call", i);
    CHECK_STATUS(sc_pointwise_map_b_to_a(p, map, n), SC_STATUS_OK);

    for (k = 0; k < 3; k++) {
        lo[k] = hi[k] = xyz_a[k];
        for (i = 1; i < n; i++) {
            lo[k] = fmin(lo[k], xyz_a[3 * i + k]);
            hi[k] = fmax(hi[k], xyz_a[3 * i + k]);
        }
        diagonal += (hi[k] - lo[k]) * (hi[k] - lo[k]);
    }
    diagonal = sqrt(diagonal);
    for (i = 0; i < n; i++) {
        double d = 0.0;
        CHECK(map[i] < n, "map[%zu] = %u is a vertex of A", i, map[i]);
        if (map[i] >= n)
            continue;
        exact += map[i] == perm[i];
        for (k = 0; k < 3; k++)
            d += (xyz_a[3 * map[i] + k] - xyz_a[3 * perm[i] + k]) *
                 (xyz_a[3 * map[i] + k] - xyz_a[3 * perm[i] + k]);
        error += sqrt(d);
    }
    error /= (double)n * diagonal;
    printf("pointwise, permuted copy of %zu vertices: %.3f exactly right, mean error %.5f of "
           "the diagonal\n",
           n, (double)exact / (double)n, error);
    CHECK((double)exact >= 0.95 * (double)n, "%.3f exactly right", (double)exact / (double)n);
    CHECK(error < 0.005, "mean error %.5f of the bounding-box diagonal", error);

    /* The functional map: ZoomOut's final size, finite, and constants map to constants
     * (both shapes have unit area, so |C[0][0]| = 1 for any vertex map). */
    rows = sc_pointwise_fmap_rows(p);
    cols = sc_pointwise_fmap_cols(p);
    CHECK(rows == (size_t)p2p_eigenpairs() && cols == rows, "fmap %zu x %zu", rows, cols);
    fmap = malloc((rows * cols + 1) * sizeof *fmap);
    fmap[0] = -7.0;
    CHECK_STATUS(sc_pointwise_fmap(p, fmap, rows * cols - 1), SC_STATUS_BUFFER_TOO_SMALL);
    CHECK(fmap[0] == -7.0, "fmap buffer untouched on failure");
    CHECK_STATUS(sc_pointwise_fmap(p, fmap, rows * cols + 1), SC_STATUS_OK);
    for (i = 0; i < rows * cols; i++)
        CHECK(isfinite(fmap[i]), "fmap[%zu] = %g", i, fmap[i]);
    CHECK(fabs(fabs(fmap[0]) - 1.0) < 1e-6, "C[0][0] = %.9f", fmap[0]);
    free(fmap);

    /* The region correspondence it was built on: an independent handle. */
    CHECK_STATUS(sc_pointwise_regions(p, NULL), SC_STATUS_NULL_ARGUMENT);
    CHECK_STATUS(sc_pointwise_regions(p, &regions), SC_STATUS_OK);
    CHECK(sc_correspondence_n_vertices(regions, SC_SIDE_B) == n, "regions of B");
    CHECK(sc_correspondence_n_matches(regions, SC_MATCHES_ONE_TO_ONE) >= 5, "%zu matches",
          sc_correspondence_n_matches(regions, SC_MATCHES_ONE_TO_ONE));
    {
        /* The map ran on the working shapes of its regions. */
        uint32_t kind = 99, regions_kind = 98;
        size_t vertices = 0, regions_vertices = 1;
        bool smoothed = true, regions_smoothed = false;
        CHECK_STATUS(sc_pointwise_working(p, SC_SIDE_B, &kind, &vertices, &smoothed),
                     SC_STATUS_OK);
        CHECK_STATUS(sc_correspondence_working(regions, SC_SIDE_B, &regions_kind,
                                               &regions_vertices, &regions_smoothed),
                     SC_STATUS_OK);
        CHECK(kind == regions_kind && vertices == regions_vertices &&
                  smoothed == regions_smoothed,
              "pointwise working %u of %zu, its regions' %u of %zu", kind, vertices,
              regions_kind, regions_vertices);
        CHECK(kind == (n < 2000 ? SC_WORKING_REFINED : SC_WORKING_INPUT), "kind %u for %zu", kind,
              n);
        CHECK_STATUS(sc_pointwise_working(p, 2, &kind, &vertices, NULL),
                     SC_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(sc_pointwise_working(p, SC_SIDE_A, NULL, &vertices, NULL),
                     SC_STATUS_NULL_ARGUMENT);
        CHECK_STATUS(sc_pointwise_working(NULL, SC_SIDE_A, &kind, &vertices, NULL),
                     SC_STATUS_NULL_ARGUMENT);
        size_t pieces = 99, left_out = 99;
        CHECK_STATUS(sc_pointwise_objects_left_out(p, SC_SIDE_B, &pieces, &left_out),
                     SC_STATUS_OK);
        CHECK(pieces == 0 && left_out == 0, "%zu pieces, %zu vertices left out", pieces,
              left_out);
        CHECK_STATUS(sc_pointwise_objects_left_out(p, 2, &pieces, NULL),
                     SC_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(sc_pointwise_objects_left_out(NULL, SC_SIDE_B, &pieces, NULL),
                     SC_STATUS_NULL_ARGUMENT);
        CHECK_STATUS(sc_pointwise_objects_not_tried(p, SC_SIDE_B, &pieces), SC_STATUS_OK);
        CHECK(pieces == 0, "%zu pieces not tried", pieces);
        CHECK_STATUS(sc_pointwise_objects_not_tried(NULL, SC_SIDE_B, &pieces),
                     SC_STATUS_NULL_ARGUMENT);
    }

    /* Confidences: the map's answer and its regions', each in range with its warning. */
    check_confidence("pointwise", sc_pointwise_confidence(p), sc_pointwise_warning(p));
    check_confidence("pointwise regions", sc_correspondence_confidence(regions),
                     sc_correspondence_warning(regions));

    CHECK_STATUS(sc_pointwise_seconds(p, "total", &total), SC_STATUS_OK);
    CHECK_STATUS(sc_pointwise_seconds(p, "eigenbasis_a", &seconds), SC_STATUS_OK);
    CHECK(total > 0.0 && seconds > 0.0 && seconds <= total, "timings %g of %g", seconds, total);
    CHECK_STATUS(sc_pointwise_seconds(p, "refinement", &seconds), SC_STATUS_OK);
    CHECK(seconds > 0.0 && seconds <= total, "refinement %g of %g", seconds, total);
    seconds = -1.0;
    CHECK_STATUS(sc_pointwise_seconds(p, "lunch", &seconds), SC_STATUS_INVALID_ARGUMENT);
    CHECK(seconds == -1.0, "no output for an unknown stage");
    CHECK_STATUS(sc_pointwise_seconds(p, NULL, &seconds), SC_STATUS_NULL_ARGUMENT);
    CHECK_STATUS(sc_pointwise_seconds(p, "total", NULL), SC_STATUS_NULL_ARGUMENT);
    /* The copy outlives the map. */
    sc_pointwise_free(p);
    p = NULL;
    CHECK(sc_correspondence_n_vertices(regions, SC_SIDE_A) == n, "regions outlive the map");
done:
    sc_correspondence_free(regions);
    sc_pointwise_free(p);
    sc_params_free(params);
    sc_shape_free(a);
    sc_shape_free(b);
    free(perm);
    free(inverse);
    free(xyz_a);
    free(xyz_b);
    free(tri_a);
    free(tri_b);
    free(map);
}

/* Cancelling at the pointwise stage: the call stops at once, nothing is written. */
static void test_pointwise_cancellation(void) {
    sc_shape *a = figure("humanoid", 0), *b = figure("humanoid", 1);
    sc_params *params = pointwise_params();
    sc_pointwise *sentinel = (sc_pointwise *)(void *)&checks, *p = sentinel;
    struct progress_log log = {0, 0, 0, SC_STAGE_POINTWISE_MAP, 0.0};
    double latency;
    if (a == NULL || b == NULL)
        return;
    CHECK_STATUS(sc_pointwise_map(a, b, params, record_progress, &log, &p),
                 SC_STATUS_CANCELLED);
    latency = now_seconds() - log.cancelled_at;
    CHECK(log.cancelled_at > 0.0, "stage %u was reported", SC_STAGE_POINTWISE_MAP);
    CHECK(latency < 0.5, "stopped %.3f s after the cancel", latency);
    CHECK(log.bad == 0, "%d bad progress calls", log.bad);
    CHECK(p == sentinel, "no output when cancelled");
    sc_params_free(params);
    sc_shape_free(a);
    sc_shape_free(b);
}

/* --------------------------------------------------------------------- concurrency */

struct shared_work {
    const sc_shape *a, *b;
    const sc_params *params;
    const uint32_t *expected_regions_b;
    size_t n_b;
    int mismatches;
    int failed;
    int error_isolated;
};

static void *match_in_thread(void *arg) {
    struct shared_work *work = (struct shared_work *)arg;
    sc_correspondence *c = NULL;
    uint32_t *regions = malloc(work->n_b * sizeof *regions);
    sc_shape *bad = NULL;
    /* Each thread's last error is its own. */
    if (sc_shape_new_point_cloud(NULL, 0, &bad) != SC_STATUS_TOO_FEW_VERTICES)
        work->failed++;
    if (sc_match(work->a, work->b, work->params, NULL, NULL, &c) != SC_STATUS_OK) {
        work->failed++;
    } else {
        if (sc_correspondence_regions(c, SC_SIDE_B, regions, work->n_b) != SC_STATUS_OK ||
            memcmp(regions, work->expected_regions_b, work->n_b * sizeof *regions) != 0)
            work->mismatches++;
        sc_correspondence_free(c);
    }
    if (strstr(sc_last_error(), "usable vertices") == NULL)
        work->error_isolated = 0;
    free(regions);
    return NULL;
}

static void test_concurrency(void) {
    enum { MAX_THREADS = 4 };
    int n_threads = quick ? 2 : MAX_THREADS, i;
    sc_shape *a = figure("quadruped", 0), *b = figure("quadruped", 2);
    sc_params *params = NULL;
    sc_correspondence *reference = NULL;
    pthread_t threads[MAX_THREADS];
    struct shared_work work[MAX_THREADS];
    uint32_t *expected;
    size_t n_b;
    if (a == NULL || b == NULL)
        return;
    CHECK_STATUS(sc_params_new(&params), SC_STATUS_OK);
    CHECK_STATUS(sc_match(a, b, params, NULL, NULL, &reference), SC_STATUS_OK);
    n_b = sc_shape_n_vertices(b);
    expected = malloc(n_b * sizeof *expected);
    CHECK_STATUS(sc_correspondence_regions(reference, SC_SIDE_B, expected, n_b), SC_STATUS_OK);
    /* Set an error on this thread: other threads' errors must not replace it. */
    CHECK_STATUS(sc_params_set_int(params, "no_such_option", 1), SC_STATUS_UNKNOWN_OPTION);
    for (i = 0; i < n_threads; i++) {
        struct shared_work w = {a, b, params, expected, n_b, 0, 0, 1};
        work[i] = w;
        CHECK(pthread_create(&threads[i], NULL, match_in_thread, &work[i]) == 0, "thread");
    }
    for (i = 0; i < n_threads; i++) {
        pthread_join(threads[i], NULL);
        CHECK(work[i].failed == 0, "thread %d failed", i);
        CHECK(work[i].mismatches == 0, "thread %d: different regions than alone", i);
        CHECK(work[i].error_isolated, "thread %d saw another thread's error", i);
    }
    CHECK(strstr(sc_last_error(), "no_such_option") != NULL, "main thread error kept: %s",
          sc_last_error());
    free(expected);
    sc_correspondence_free(reference);
    sc_params_free(params);
    sc_shape_free(a);
    sc_shape_free(b);
}

/* kmeans_restarts at its largest (minutes of work) stops promptly. */
static bool cancel_in_segmentation(void *userdata, uint32_t stage, float fraction) {
    double *due = (double *)userdata;
    (void)fraction;
    if (stage != SC_STAGE_SEGMENTATION)
        return true;
    if (*due == 0.0)
        *due = now_seconds() + 0.3;
    return now_seconds() < *due;
}

static void test_cancel_huge_restarts(void) {
    sc_shape *a = figure("humanoid", 0), *b = figure("humanoid", 1);
    sc_params *params = NULL;
    sc_correspondence *c = NULL;
    /* Under valgrind (quick mode) everything runs 20-50x slower and the threads take turns,
     * so the bound there is the plain one times 50 (49 s was seen once with 30); without the
     * cancel the restarts would run for hours there. */
    double due = 0.0, latency, limit = quick ? 100.0 : 2.0;
    CHECK_STATUS(sc_params_new(&params), SC_STATUS_OK);
    CHECK_STATUS(sc_params_set_int(params, "kmeans_restarts", 1000), SC_STATUS_OK);
    CHECK_STATUS(sc_match(a, b, params, cancel_in_segmentation, &due, &c), SC_STATUS_CANCELLED);
    latency = now_seconds() - due;
    CHECK(due > 0.0 && latency < limit, "stopped %.3f s after the cancel", latency);
    CHECK(c == NULL, "no output when cancelled");
    sc_params_free(params);
    sc_shape_free(a);
    sc_shape_free(b);
}

/* --------------------------------------------------------------------------- transfer */

static bool cancel_transfer(void *userdata, uint32_t stage, float fraction) {
    int *calls = (int *)userdata;
    (void)fraction;
    if (stage == SC_STAGE_TRANSFER)
        (*calls)++;
    return stage != SC_STAGE_TRANSFER;
}

/* A map between two poses of a figure, its surface map and the three transfer modes. */
static void test_transfer(void) {
    sc_shape *a = figure("humanoid", 0), *b = figure("humanoid", 2), *other = figure("star5", 0);
    sc_params *params = pointwise_params();
    sc_pointwise *p = NULL;
    sc_surface_map *m = NULL, *sentinel = (sc_surface_map *)&m;
    size_t na, nb, i, k;
    double *xyz_a, *x_a, *out, *weights, *rows;
    uint32_t *corners;
    int calls = 0;
    CHECK_STATUS(sc_pointwise_map(a, b, params, NULL, NULL, &p), SC_STATUS_OK);
    if (p == NULL)
        goto done;
    na = sc_shape_n_vertices(a);
    nb = sc_shape_n_vertices(b);
    /* Errors: NULLs, shapes that are not the map's, a cancel. */
    CHECK_STATUS(sc_surface_map_new(NULL, b, p, NULL, NULL, &m), SC_STATUS_NULL_ARGUMENT);
    CHECK_STATUS(sc_surface_map_new(a, b, NULL, NULL, NULL, &m), SC_STATUS_NULL_ARGUMENT);
    CHECK_STATUS(sc_surface_map_new(a, b, p, NULL, NULL, NULL), SC_STATUS_NULL_ARGUMENT);
    m = sentinel;
    CHECK_STATUS(sc_surface_map_new(other, b, p, NULL, NULL, &m), SC_STATUS_INVALID_ARGUMENT);
    CHECK(strstr(sc_last_error(), "vertices") != NULL, "message: %s", sc_last_error());
    CHECK_STATUS(sc_surface_map_new(a, b, p, cancel_transfer, &calls, &m), SC_STATUS_CANCELLED);
    CHECK(calls == 1 && m == sentinel, "cancelled at the first report, nothing written");
    CHECK_STATUS(sc_surface_map_new(a, b, p, NULL, NULL, &m), SC_STATUS_OK);
    CHECK(sc_surface_map_n_vertices(m, SC_SIDE_A) == na, "n A");
    CHECK(sc_surface_map_n_vertices(m, SC_SIDE_B) == nb, "n B");
    CHECK(sc_surface_map_n_vertices(m, 5) == 0 && sc_surface_map_n_vertices(NULL, 0) == 0,
          "bad side, NULL");

    xyz_a = malloc(3 * na * sizeof *xyz_a);
    x_a = malloc(na * sizeof *x_a);
    out = malloc(2 * nb * sizeof *out);
    weights = malloc(3 * nb * sizeof *weights);
    corners = malloc(3 * nb * sizeof *corners);
    rows = malloc(2 * na * sizeof *rows);
    CHECK_STATUS(sc_shape_vertices(a, xyz_a, 3 * na), SC_STATUS_OK);
    CHECK_STATUS(sc_surface_map_points(m, corners, weights, 3 * nb - 1),
                 SC_STATUS_BUFFER_TOO_SMALL);
    CHECK_STATUS(sc_surface_map_points(m, corners, weights, 3 * nb), SC_STATUS_OK);
    /* Interpolation of A's x coordinate is the points' weighted x. */
    for (i = 0; i < na; i++)
        x_a[i] = xyz_a[3 * i];
    CHECK_STATUS(sc_surface_map_transfer(m, x_a, na, 1, SC_TRANSFER_INTERPOLATE, 0, out, nb),
                 SC_STATUS_OK);
    for (i = 0; i < nb; i++) {
        double x = 0.0, total = 0.0;
        for (k = 0; k < 3; k++) {
            CHECK(corners[3 * i + k] < na, "corner %u", corners[3 * i + k]);
            x += weights[3 * i + k] * x_a[corners[3 * i + k] % na];
            total += weights[3 * i + k];
        }
        CHECK(fabs(total - 1.0) < 1e-9 && fabs(out[i] - x) < 1e-9, "vertex %zu", i);
    }
    /* Nearest carries the heaviest corner's value. */
    CHECK_STATUS(sc_surface_map_transfer(m, x_a, na, 1, SC_TRANSFER_NEAREST, 0, out, nb),
                 SC_STATUS_OK);
    for (i = 0; i < nb; i++)
        CHECK(out[i] == x_a[corners[3 * i] % na], "nearest at %zu", i);
    /* Skin weights over two bones, one influence kept: a single 1 per row. */
    for (i = 0; i < na; i++) {
        rows[2 * i] = xyz_a[3 * i + 1] > 0.0 ? 0.8 : 0.3;
        rows[2 * i + 1] = 1.0 - rows[2 * i];
    }
    CHECK_STATUS(sc_surface_map_transfer(m, rows, 2 * na, 2, SC_TRANSFER_WEIGHTS, 1, out, 2 * nb),
                 SC_STATUS_OK);
    for (i = 0; i < nb; i++)
        CHECK(out[2 * i] + out[2 * i + 1] == 1.0 && out[2 * i] * out[2 * i + 1] == 0.0,
              "one influence at %zu", i);
    /* Bad values and modes are refused, naming the vertex; the output is left alone. */
    out[0] = -7.0;
    CHECK_STATUS(sc_surface_map_transfer(m, rows, 2 * na - 1, 2, SC_TRANSFER_WEIGHTS, 1, out,
                                         2 * nb),
                 SC_STATUS_INVALID_PARAMETER);
    CHECK_STATUS(sc_surface_map_transfer(m, rows, 2 * na, 2, 7, 1, out, 2 * nb),
                 SC_STATUS_INVALID_ARGUMENT);
    rows[5] = -0.5;
    CHECK_STATUS(sc_surface_map_transfer(m, rows, 2 * na, 2, SC_TRANSFER_WEIGHTS, 0, out, 2 * nb),
                 SC_STATUS_INVALID_PARAMETER);
    CHECK(strstr(sc_last_error(), "vertex 2") != NULL, "message: %s", sc_last_error());
    rows[5] = NAN;
    CHECK_STATUS(sc_surface_map_transfer(m, rows, 2 * na, 2, SC_TRANSFER_INTERPOLATE, 0, out,
                                         2 * nb),
                 SC_STATUS_INVALID_PARAMETER);
    CHECK_STATUS(sc_surface_map_transfer(m, x_a, na, 1, SC_TRANSFER_INTERPOLATE, 0, out, nb - 1),
                 SC_STATUS_BUFFER_TOO_SMALL);
    CHECK_STATUS(sc_surface_map_transfer(m, NULL, na, 1, SC_TRANSFER_INTERPOLATE, 0, out, nb),
                 SC_STATUS_NULL_ARGUMENT);
    CHECK(out[0] == -7.0, "output untouched by failed calls");
    /* Per-corner values: a constant per triangle corner carries to the same constant. */
    {
        size_t nta = sc_shape_n_triangles(a), ntb = sc_shape_n_triangles(b);
        uint32_t *faces_a = malloc(3 * nta * sizeof *faces_a), *faces_b = malloc(3 * ntb * sizeof *faces_b);
        double *corner_a = malloc(3 * nta * sizeof *corner_a), *corner_b = malloc(3 * ntb * sizeof *corner_b);
        CHECK_STATUS(sc_shape_triangles(a, faces_a, 3 * nta), SC_STATUS_OK);
        CHECK_STATUS(sc_shape_triangles(b, faces_b, 3 * ntb), SC_STATUS_OK);
        for (i = 0; i < 3 * nta; i++)
            corner_a[i] = 0.25;
        CHECK_STATUS(sc_surface_map_transfer_corners(m, a, faces_a, 3 * nta, corner_a, 3 * nta, faces_b,
                                                     3 * ntb, 1, corner_b, 3 * ntb),
                     SC_STATUS_OK);
        for (i = 0; i < 3 * ntb; i++)
            CHECK(fabs(corner_b[i] - 0.25) < 1e-12, "corner %zu: %g", i, corner_b[i]);
        CHECK_STATUS(sc_surface_map_transfer_corners(m, a, faces_a, 3 * nta - 1, corner_a, 3 * nta,
                                                     faces_b, 3 * ntb, 1, corner_b, 3 * ntb),
                     SC_STATUS_INVALID_ARGUMENT);
        CHECK_STATUS(sc_surface_map_transfer_corners(m, a, faces_a, 3 * nta, corner_a, 3 * nta - 3,
                                                     faces_b, 3 * ntb, 1, corner_b, 3 * ntb),
                     SC_STATUS_INVALID_PARAMETER);
        free(faces_a);
        free(faces_b);
        free(corner_a);
        free(corner_b);
    }
    free(xyz_a);
    free(x_a);
    free(out);
    free(weights);
    free(corners);
    free(rows);
done:
    sc_surface_map_free(m == sentinel ? NULL : m);
    sc_surface_map_free(NULL);
    sc_pointwise_free(p);
    sc_params_free(params);
    sc_shape_free(a);
    sc_shape_free(b);
    sc_shape_free(other);
}

/* Frees `handle` (of the kind `free_fn` frees) at the first progress report. */
struct free_at_report {
    void *handle;
    void (*free_fn)(void *);
    int reports;
};

static bool free_at_first_report(void *userdata, uint32_t stage, float fraction) {
    struct free_at_report *f = userdata;
    (void)stage;
    (void)fraction;
    if (f->reports++ == 0)
        f->free_fn(f->handle);
    return true;
}

static void free_shape(void *h) { sc_shape_free(h); }
static void free_params(void *h) { sc_params_free(h); }
static void free_pointwise(void *h) { sc_pointwise_free(h); }

/* A handle freed while a call uses it (from the call's own progress callback) stays alive
 * until the call returns: the call's answer is whole, and valgrind sees no read of freed
 * memory (before handles were counted: a PANIC status reading the freed shape). */
static void test_handles_in_use(void) {
    sc_shape *a = figure("humanoid", 0), *b = figure("humanoid", 3), *a2 = figure("humanoid", 0);
    sc_params *params = pointwise_params();
    sc_correspondence *c = NULL;
    sc_pointwise *p = NULL;
    sc_surface_map *m = NULL;
    size_t na = sc_shape_n_vertices(a), nb = sc_shape_n_vertices(b);
    sc_symmetry *s = NULL;
    sc_params *quick_params = NULL; /* unverified: the same handles, a third of the work */
    struct free_at_report f = {NULL, free_shape, 0};
    CHECK_STATUS(sc_params_new(&quick_params), SC_STATUS_OK);
    CHECK_STATUS(sc_params_set_bool(quick_params, "verify_hypotheses", false), SC_STATUS_OK);
    f.handle = a;
    CHECK_STATUS(sc_match(a, b, quick_params, free_at_first_report, &f, &c), SC_STATUS_OK);
    CHECK(f.reports > 1, "freed at the first of %d reports", f.reports);
    CHECK(sc_correspondence_n_vertices(c, SC_SIDE_A) == na, "regions of every vertex of A");
    f.handle = params, f.free_fn = free_params, f.reports = 0;
    CHECK_STATUS(sc_pointwise_map(a2, b, params, free_at_first_report, &f, &p), SC_STATUS_OK);
    CHECK(f.reports > 1 && sc_pointwise_n_vertices(p, SC_SIDE_B) == nb, "a map of B");
    f.handle = p, f.free_fn = free_pointwise, f.reports = 0;
    CHECK_STATUS(sc_surface_map_new(a2, b, p, free_at_first_report, &f, &m), SC_STATUS_OK);
    CHECK(f.reports > 0 && sc_surface_map_n_vertices(m, SC_SIDE_B) == nb, "surface map made");
    f.handle = b, f.free_fn = free_shape, f.reports = 0;
    CHECK_STATUS(sc_symmetry_detect(b, quick_params, free_at_first_report, &f, &s), SC_STATUS_OK);
    CHECK(f.reports > 1 && sc_symmetry_n_vertices(s) == nb, "symmetry of every vertex");
    sc_symmetry_free(s);
    sc_surface_map_free(m);
    sc_correspondence_free(c);
    sc_params_free(quick_params);
    sc_shape_free(a2);
}

/* A surface map checks its shapes by their positions and faces, not only their counts. */
static void test_surface_map_shapes(void) {
    sc_shape *a = figure("humanoid", 0), *b = figure("humanoid", 3), *c = figure("humanoid", 5);
    sc_params *params = pointwise_params();
    sc_pointwise *p = NULL;
    sc_surface_map *m = NULL, *sentinel = (sc_surface_map *)&m;
    size_t na = sc_shape_n_vertices(a), nb = sc_shape_n_vertices(b), i;
    size_t nta = sc_shape_n_triangles(a), ntb = sc_shape_n_triangles(b);
    uint32_t *faces_a = malloc(3 * nta * sizeof *faces_a), *faces_b = malloc(3 * ntb * sizeof *faces_b);
    uint32_t *nearest = malloc(nb * sizeof *nearest), *corners = malloc(3 * nb * sizeof *corners);
    double *values = malloc(4 * na * sizeof *values), *out = malloc(4 * nb * sizeof *out);
    double *corner_a = calloc(3 * nta, sizeof *corner_a), *corner_b = malloc(3 * ntb * sizeof *corner_b);
    double *weights = malloc(3 * nb * sizeof *weights);
    CHECK(na == nb && sc_shape_n_vertices(c) == na, "three figures of one size");
    CHECK_STATUS(sc_pointwise_map(a, b, params, NULL, NULL, &p), SC_STATUS_OK);
    m = sentinel;
    CHECK_STATUS(sc_surface_map_new(b, a, p, NULL, NULL, &m), SC_STATUS_INVALID_ARGUMENT);
    CHECK(strstr(sc_last_error(), "swapped") != NULL, "message: %s", sc_last_error());
    CHECK_STATUS(sc_surface_map_new(c, b, p, NULL, NULL, &m), SC_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(sc_surface_map_new(a, c, p, NULL, NULL, &m), SC_STATUS_INVALID_ARGUMENT);
    CHECK(strstr(sc_last_error(), "not the shape B") != NULL, "message: %s", sc_last_error());
    CHECK(m == sentinel, "nothing written on failure");
    CHECK_STATUS(sc_surface_map_new(a, b, p, NULL, NULL, &m), SC_STATUS_OK);
    if (m == sentinel) m = NULL;
    CHECK_STATUS(sc_shape_triangles(a, faces_a, 3 * nta), SC_STATUS_OK);
    CHECK_STATUS(sc_shape_triangles(b, faces_b, 3 * ntb), SC_STATUS_OK);
    /* Per-corner transfer: A's faces required, all of them, and A itself. */
    for (i = 0; i < 3 * ntb; i++) corner_b[i] = -7.0;
    CHECK_STATUS(sc_surface_map_transfer_corners(m, a, faces_a, 0, NULL, 0, faces_b, 3 * ntb, 1,
                                                 corner_b, 3 * ntb),
                 SC_STATUS_INVALID_PARAMETER);
    CHECK(strstr(sc_last_error(), "empty") != NULL, "message: %s", sc_last_error());
    CHECK(corner_b[0] == -7.0, "output untouched");
    CHECK_STATUS(sc_surface_map_transfer_corners(m, c, faces_a, 3 * nta, corner_a, 3 * nta,
                                                 faces_b, 3 * ntb, 1, corner_b, 3 * ntb),
                 SC_STATUS_INVALID_PARAMETER);
    CHECK(strstr(sc_last_error(), "not the shape A") != NULL, "message: %s", sc_last_error());
    CHECK_STATUS(sc_surface_map_transfer_corners(m, a, faces_a + 3, 3 * nta - 3, corner_a + 3,
                                                 3 * nta - 3, faces_b, 3 * ntb, 1, corner_b, 3 * ntb),
                 SC_STATUS_INVALID_PARAMETER);
    CHECK(strstr(sc_last_error(), "every triangle") != NULL, "message: %s", sc_last_error());
    CHECK_STATUS(sc_surface_map_transfer_corners(m, a, faces_a, 3 * nta, corner_a, 3 * nta,
                                                 faces_b, 3 * ntb, 1, corner_b, 3 * ntb),
                 SC_STATUS_OK);
    /* Values near the largest double: a constant stays itself, skin weights sum to 1. */
    for (i = 0; i < 4 * na; i++) values[i] = 1.7e308;
    CHECK_STATUS(sc_surface_map_transfer(m, values, 4 * na, 4, SC_TRANSFER_INTERPOLATE, 0, out,
                                         4 * nb),
                 SC_STATUS_OK);
    for (i = 0; i < 4 * nb; i++) CHECK(out[i] == 1.7e308, "constant at %zu: %g", i, out[i]);
    CHECK_STATUS(sc_surface_map_transfer(m, values, 4 * na, 4, SC_TRANSFER_WEIGHTS, 0, out, 4 * nb),
                 SC_STATUS_OK);
    for (i = 0; i < nb; i++) {
        double sum = out[4 * i] + out[4 * i + 1] + out[4 * i + 2] + out[4 * i + 3];
        CHECK(fabs(sum - 1.0) < 1e-12, "row %zu sums to %g", i, sum);
    }
    /* The nearest vertex is the heaviest of the three, as SC_TRANSFER_NEAREST reads it. */
    CHECK_STATUS(sc_surface_map_nearest(m, nearest, nb - 1), SC_STATUS_BUFFER_TOO_SMALL);
    CHECK_STATUS(sc_surface_map_nearest(m, nearest, nb), SC_STATUS_OK);
    CHECK_STATUS(sc_surface_map_points(m, corners, weights, 3 * nb), SC_STATUS_OK);
    for (i = 0; i < nb; i++) CHECK(nearest[i] == corners[3 * i], "nearest of %zu", i);
    sc_surface_map_free(m);
    sc_pointwise_free(p);
    sc_params_free(params);
    sc_shape_free(a);
    sc_shape_free(b);
    sc_shape_free(c);
    free(faces_a);
    free(faces_b);
    free(nearest);
    free(corners);
    free(values);
    free(out);
    free(corner_a);
    free(corner_b);
    free(weights);
}

/* Too small a gap ratio leaves every region with too many candidates: an error that names
 * gap_ratio, never a success with no match; 0 (in the documented range [0, 1]) is taken. */
static void test_no_match_is_an_error(void) {
    sc_shape *a = figure("humanoid", 0), *b = figure("humanoid", 3);
    sc_params *params = NULL;
    sc_correspondence *c = NULL;
    sc_pointwise *p = NULL;
    double values[] = {1e-20, 0.0};
    size_t i;
    CHECK_STATUS(sc_params_new(&params), SC_STATUS_OK);
    CHECK_STATUS(sc_params_set_bool(params, "verify_hypotheses", false), SC_STATUS_OK);
    for (i = 0; i < 2; i++) {
        CHECK_STATUS(sc_params_set_double(params, "gap_ratio", values[i]), SC_STATUS_OK);
        CHECK_STATUS(sc_match(a, b, params, NULL, NULL, &c), SC_STATUS_INVALID_PARAMETER);
        CHECK(strstr(sc_last_error(), "gap_ratio") && strstr(sc_last_error(), "no region"),
              "message: %s", sc_last_error());
        CHECK_STATUS(sc_pointwise_map(a, b, params, NULL, NULL, &p), SC_STATUS_INVALID_PARAMETER);
        CHECK(strstr(sc_last_error(), "gap_ratio") != NULL, "message: %s", sc_last_error());
    }
    CHECK(c == NULL && p == NULL, "nothing written");
    sc_params_free(params);
    sc_shape_free(a);
    sc_shape_free(b);
}

/* ---------------------------------------------------------------- collections */

/* Writes `shape` as an OFF file. */
static void write_off(const sc_shape *shape, const char *path) {
    size_t n = sc_shape_n_vertices(shape), t = sc_shape_n_triangles(shape), i;
    double *xyz = malloc(3 * n * sizeof *xyz);
    uint32_t *tri = malloc(3 * t * sizeof *tri);
    FILE *f = fopen(path, "w");
    CHECK(xyz && tri && f, "allocations and %s", path);
    if (!(xyz && tri && f)) return;
    CHECK_STATUS(sc_shape_vertices(shape, xyz, 3 * n), SC_STATUS_OK);
    CHECK_STATUS(sc_shape_triangles(shape, tri, 3 * t), SC_STATUS_OK);
    fprintf(f, "OFF\n%zu %zu 0\n", n, t);
    for (i = 0; i < n; i++) fprintf(f, "%.17g %.17g %.17g\n", xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    for (i = 0; i < t; i++) fprintf(f, "3 %u %u %u\n", tri[3 * i], tri[3 * i + 1], tri[3 * i + 2]);
    fclose(f);
    free(xyz);
    free(tri);
}

static void test_batch(void) {
    char dir[] = "/tmp/shapecorr_c_batch_XXXXXX";
    char a_path[128], b_path[128], cache[128], missing[128];
    sc_batch *batch = NULL, *again = NULL;
    sc_batch_record *record = NULL;
    sc_correspondence *alone = NULL;
    sc_params *params = NULL;
    char command[160];
    sc_shape *a = figure("humanoid", 0), *b = figure("humanoid", 2);
    const char *json;
    char expected_k[32];
    CHECK(mkdtemp(dir) != NULL, "temporary folder");
    snprintf(a_path, sizeof a_path, "%s/a.off", dir);
    snprintf(b_path, sizeof b_path, "%s/b.off", dir);
    snprintf(cache, sizeof cache, "%s/cache", dir);
    snprintf(missing, sizeof missing, "%s/missing.ply", dir);
    write_off(a, a_path);
    write_off(b, b_path);

    /* A cheap pipeline (this tests the API; under valgrind the defaults took minutes). */
    CHECK_STATUS(sc_params_new(&params), SC_STATUS_OK);
    CHECK_STATUS(sc_params_set_int(params, "k_max", 5), SC_STATUS_OK);
    CHECK_STATUS(sc_params_set_int(params, "eigenpairs", 30), SC_STATUS_OK);
    CHECK_STATUS(sc_params_set_bool(params, "verify_hypotheses", false), SC_STATUS_OK);
    CHECK_STATUS(sc_params_set_bool(params, "hks_fallback", false), SC_STATUS_OK);

    CHECK_STATUS(sc_batch_new(params, cache, 0, NULL), SC_STATUS_NULL_ARGUMENT);
    CHECK_STATUS(sc_batch_new(params, NULL, 0, &batch), SC_STATUS_NULL_ARGUMENT);
    CHECK_STATUS(sc_batch_new(params, cache, 64, &batch), SC_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(sc_batch_new(params, cache, 0, &batch), SC_STATUS_OK);

    /* The per-shape job: computed once, then from the cache (in another batch too). */
    CHECK_STATUS(sc_batch_prepare(batch, "a", a_path, &record), SC_STATUS_OK);
    CHECK(sc_batch_record_ok(record), "a prepared: %s", sc_batch_record_json(record));
    CHECK(strstr(sc_batch_record_json(record), "\"computed\":true") != NULL, "%s",
          sc_batch_record_json(record));
    sc_batch_record_free(record);
    CHECK_STATUS(sc_batch_new(params, cache, 0, &again), SC_STATUS_OK);
    CHECK_STATUS(sc_batch_prepare(again, "a", a_path, &record), SC_STATUS_OK);
    CHECK(strstr(sc_batch_record_json(record), "\"computed\":false") != NULL, "%s",
          sc_batch_record_json(record));
    sc_batch_record_free(record);
    sc_batch_free(again);

    /* The per-pair job: the answer of sc_match on the same shapes. */
    CHECK_STATUS(sc_batch_match(batch, "a", a_path, "b", b_path, dir, &record), SC_STATUS_OK);
    json = sc_batch_record_json(record);
    CHECK(sc_batch_record_ok(record) && strstr(json, "\"ok\":true") != NULL, "%.200s", json);
    CHECK_STATUS(sc_match(a, b, params, NULL, NULL, &alone), SC_STATUS_OK);
    snprintf(expected_k, sizeof expected_k, "\"k\":%u,", sc_correspondence_k(alone));
    CHECK(strstr(json, expected_k) != NULL, "%s in %.200s", expected_k, json);
    sc_correspondence_free(alone);
    sc_batch_record_free(record);

    /* A shape that cannot be read: a failed record naming the file, not a failed call. */
    CHECK_STATUS(sc_batch_match(batch, "a", a_path, "gone", missing, dir, &record), SC_STATUS_OK);
    CHECK(!sc_batch_record_ok(record), "a missing file fails the pair");
    CHECK(strstr(sc_batch_record_json(record), "missing.ply") != NULL, "%s",
          sc_batch_record_json(record));
    sc_batch_record_free(record);
    CHECK_STATUS(sc_batch_match(batch, NULL, a_path, "b", b_path, dir, &record),
                 SC_STATUS_NULL_ARGUMENT);

    /* The output folder: held by one opener at a time, released by its free. */
    {
        sc_batch_folder *folder = NULL, *second = NULL;
        char out[160], pairs[160];
        FILE *f;
        snprintf(out, sizeof out, "%s/out", dir);
        CHECK_STATUS(sc_batch_open_folder(batch, out, NULL), SC_STATUS_NULL_ARGUMENT);
        CHECK_STATUS(sc_batch_open_folder(batch, out, &folder), SC_STATUS_OK);
        CHECK_STATUS(sc_batch_open_folder(batch, out, &second), SC_STATUS_FILE_ERROR);
        CHECK(second == NULL, "no folder on failure");
        sc_batch_folder_free(folder);
        CHECK_STATUS(sc_batch_open_folder(batch, out, &second), SC_STATUS_OK);
        sc_batch_folder_free(second);
        sc_batch_folder_free(NULL);

        /* Pair files: tab-separated names may hold spaces. */
        snprintf(pairs, sizeof pairs, "%s/pairs.txt", dir);
        f = fopen(pairs, "w");
        CHECK(f != NULL, "%s", pairs);
        if (f) {
            fputs("# a\tb\nleft arm\tb\n", f);
            fclose(f);
        }
        CHECK_STATUS(sc_batch_read_pairs(pairs, &record), SC_STATUS_OK);
        CHECK(strstr(sc_batch_record_json(record), "\"a\":\"left arm\"") != NULL, "%s",
              sc_batch_record_json(record));
        sc_batch_record_free(record);
        CHECK_STATUS(sc_batch_read_pairs(missing, &record), SC_STATUS_FILE_ERROR);
        CHECK_STATUS(sc_batch_read_pairs(NULL, &record), SC_STATUS_NULL_ARGUMENT);
    }
    CHECK(sc_batch_record_json(NULL) == NULL && !sc_batch_record_ok(NULL), "NULL record");
    sc_batch_record_free(NULL);
    sc_batch_free(NULL);
    sc_batch_free(batch);
    sc_params_free(params);
    sc_shape_free(a);
    sc_shape_free(b);
    snprintf(command, sizeof command, "rm -rf '%s'", dir);
    CHECK(system(command) == 0, "%s", command);
}

/* Every test, in the order a plain run takes them. */
/* -------------------------------------------------- placement, landmarks, other answer */

/* Landmarks given with the parameters map exactly to their partners; the verdict names the
 * chosen hypothesis, the runner-up, what decided and the turns; the other answer is the
 * runner-up's map, different from the first, and a surface map accepts it. The figures of
 * one kind and size share their vertex order, so (v, v) pairs are true landmarks. */
static void test_landmarks_and_other_answer(void) {
    sc_shape *a = figure("humanoid", 0), *b = figure("humanoid", 3);
    sc_params *params = pointwise_params();
    sc_pointwise *p = NULL, *other = NULL, *back = NULL;
    sc_correspondence *regions = NULL, *other_regions = NULL;
    sc_surface_map *m = NULL;
    size_t nb = sc_shape_n_vertices(b), i, differ = 0;
    uint32_t pairs[4], got[4] = {0, 0, 0, 0};
    uint32_t *map = malloc(nb * sizeof *map), *other_map = malloc(nb * sizeof *other_map);
    const char *chosen, *runner_up, *decided;
    int64_t placement = -1;
    pairs[0] = pairs[1] = (uint32_t)(nb / 7);
    pairs[2] = pairs[3] = (uint32_t)(3 * nb / 5);
    CHECK_STATUS(sc_params_set_int(params, "placement", SC_PLACEMENT_IGNORE), SC_STATUS_OK);
    CHECK_STATUS(sc_params_get_int(params, "placement", &placement), SC_STATUS_OK);
    CHECK(placement == SC_PLACEMENT_IGNORE, "placement %lld", (long long)placement);
    CHECK_STATUS(sc_params_set_int(params, "placement", 3), SC_STATUS_INVALID_PARAMETER);
    CHECK_STATUS(sc_params_set_landmarks(params, pairs, 2), SC_STATUS_OK);
    CHECK(sc_params_n_landmarks(params) == 2, "%zu landmarks", sc_params_n_landmarks(params));
    CHECK_STATUS(sc_params_landmarks(params, got, 3), SC_STATUS_BUFFER_TOO_SMALL);
    CHECK_STATUS(sc_params_landmarks(params, got, 4), SC_STATUS_OK);
    CHECK(memcmp(got, pairs, sizeof pairs) == 0, "landmarks read back %u %u %u %u", got[0],
          got[1], got[2], got[3]);

    CHECK_STATUS(sc_pointwise_map(a, b, params, NULL, NULL, &p), SC_STATUS_OK);
    if (p == NULL || map == NULL || other_map == NULL)
        goto done;
    CHECK_STATUS(sc_pointwise_map_b_to_a(p, map, nb), SC_STATUS_OK);
    CHECK(map[pairs[1]] == pairs[0] && map[pairs[3]] == pairs[2],
          "landmarks map to their partners: %u -> %u, %u -> %u", pairs[1], map[pairs[1]],
          pairs[3], map[pairs[3]]);

    chosen = sc_pointwise_hypothesis(p, SC_ANSWER_CHOSEN);
    runner_up = sc_pointwise_hypothesis(p, SC_ANSWER_RUNNER_UP);
    decided = sc_pointwise_decided_by(p);
    CHECK(chosen != NULL && decided != NULL, "a verified answer names its hypothesis");
    CHECK(runner_up != NULL, "a humanoid pair has a runner-up (its mirror image at least)");
    if (chosen == NULL || runner_up == NULL || decided == NULL)
        goto done;
    CHECK(strcmp(decided, "cost") == 0 || strcmp(decided, "close call") == 0 ||
              strcmp(decided, "landmarks") == 0,
          "placement ignored: decided by %s", decided);
    CHECK(!sc_pointwise_placement_used(p), "placement ignored, yet used");
    CHECK(sc_pointwise_hypothesis(p, SC_ANSWER_CHOSEN) == chosen, "the handle owns the name");
    CHECK(strcmp(chosen, runner_up) != 0, "chosen %s, runner-up %s", chosen, runner_up);
    for (i = 0; i < 2; i++) {
        double cost = sc_pointwise_hypothesis_cost(p, (uint32_t)i);
        double turn = sc_pointwise_turn_degrees(p, (uint32_t)i);
        CHECK(isfinite(cost) && cost >= 0.0, "cost %g of hypothesis %zu", cost, i);
        CHECK(turn >= 0.0 && turn <= 180.0, "turn %g of hypothesis %zu", turn, i);
    }
    CHECK(sc_pointwise_hypothesis(p, 2) == NULL, "which 2 is no hypothesis");
    CHECK(strstr(sc_last_error(), "SC_ANSWER_RUNNER_UP") != NULL, "message: %s",
          sc_last_error());
    CHECK(isnan(sc_pointwise_hypothesis_cost(p, 2)) && isnan(sc_pointwise_turn_degrees(p, 2)),
          "NaN for which 2");

    /* The other answer: the runner-up's map, decided by "other answer". */
    CHECK_STATUS(sc_pointwise_other_answer(p, NULL), SC_STATUS_NULL_ARGUMENT);
    CHECK_STATUS(sc_pointwise_other_answer(p, &other), SC_STATUS_OK);
    if (other == NULL)
        goto done;
    CHECK_STATUS(sc_pointwise_map_b_to_a(other, other_map, nb), SC_STATUS_OK);
    for (i = 0; i < nb; i++)
        differ += other_map[i] != map[i];
    CHECK(differ > nb / 10, "the other answer moves %zu of %zu vertices", differ, nb);
    CHECK(other_map[pairs[1]] == pairs[0] && other_map[pairs[3]] == pairs[2],
          "the other answer keeps the landmarks pinned: %u, %u", other_map[pairs[1]],
          other_map[pairs[3]]);
    CHECK(strcmp(sc_pointwise_hypothesis(other, SC_ANSWER_CHOSEN), runner_up) == 0,
          "the other answer is the runner-up %s, got %s", runner_up,
          sc_pointwise_hypothesis(other, SC_ANSWER_CHOSEN));
    CHECK(strcmp(sc_pointwise_decided_by(other), "other answer") == 0, "decided by %s",
          sc_pointwise_decided_by(other));
    CHECK(sc_pointwise_hypothesis_cost(other, SC_ANSWER_CHOSEN) ==
              sc_pointwise_hypothesis_cost(p, SC_ANSWER_RUNNER_UP),
          "the same cost, nothing recomputed");
    CHECK(sc_pointwise_n_vertices(other, SC_SIDE_A) == sc_pointwise_n_vertices(p, SC_SIDE_A),
          "the same shapes");
    CHECK_STATUS(sc_surface_map_new(a, b, other, NULL, NULL, &m), SC_STATUS_OK);
    CHECK(sc_surface_map_n_vertices(m, SC_SIDE_B) == nb, "surface map of the other answer");
    /* Its own other answer exists too (the first one, usually), a handle of its own. */
    CHECK_STATUS(sc_pointwise_other_answer(other, &back), SC_STATUS_OK);

    /* Two whole figures: taken as whole by the measurement; B's image covers nearly all of
     * A, and every vertex of B has a counterpart; the other answer has its own A mask. */
    {
        size_t na = sc_pointwise_n_vertices(p, SC_SIDE_A), covered = 0;
        bool given = true, *mask = malloc((na > nb ? na : nb) * sizeof *mask);
        double share = sc_pointwise_covered_share(p);
        const char *taken_as = sc_pointwise_taken_as(p, &given);
        CHECK(taken_as != NULL && strcmp(taken_as, "whole") == 0 && !given, "taken as %s%s",
              taken_as ? taken_as : "NULL", given ? " (given)" : "");
        CHECK(sc_pointwise_taken_as(p, NULL) == taken_as, "static name, out_given optional");
        CHECK(share > 0.9 && share <= 1.0, "covered share %g", share);
        if (mask != NULL) {
            CHECK_STATUS(sc_pointwise_covered(p, SC_SIDE_A, mask, na), SC_STATUS_OK);
            for (i = 0; i < na; i++)
                covered += mask[i];
            CHECK(covered * 10 >= na * 9, "%zu of %zu vertices of A covered", covered, na);
            CHECK_STATUS(sc_pointwise_covered(p, SC_SIDE_B, mask, nb), SC_STATUS_OK);
            for (i = 0, covered = 0; i < nb; i++)
                covered += mask[i];
            CHECK(covered == nb, "%zu of %zu vertices of B covered", covered, nb);
            CHECK_STATUS(sc_pointwise_covered(p, SC_SIDE_B, mask, nb - 1),
                         SC_STATUS_BUFFER_TOO_SMALL);
            CHECK_STATUS(sc_pointwise_covered(p, 2, mask, nb), SC_STATUS_INVALID_ARGUMENT);
            CHECK_STATUS(sc_pointwise_covered(p, SC_SIDE_A, NULL, na), SC_STATUS_NULL_ARGUMENT);
            CHECK_STATUS(sc_pointwise_covered(other, SC_SIDE_A, mask, na), SC_STATUS_OK);
            CHECK(isfinite(sc_pointwise_covered_share(other)), "the other answer's share");
        }
        free(mask);
    }

    /* The region results carry the same verdict and give their own other answer. */
    CHECK_STATUS(sc_pointwise_regions(p, &regions), SC_STATUS_OK);
    if (regions != NULL) {
        CHECK(strcmp(sc_correspondence_hypothesis(regions, SC_ANSWER_CHOSEN), chosen) == 0,
              "the regions' verdict is the map's");
        CHECK(strcmp(sc_correspondence_decided_by(regions), decided) == 0, "decided by %s",
              sc_correspondence_decided_by(regions));
        CHECK(sc_correspondence_turn_degrees(regions, SC_ANSWER_RUNNER_UP) ==
                  sc_pointwise_turn_degrees(p, SC_ANSWER_RUNNER_UP),
              "the same runner-up");
        CHECK(!sc_correspondence_placement_used(regions), "placement ignored");
        CHECK_STATUS(sc_correspondence_other_answer(regions, &other_regions), SC_STATUS_OK);
        if (other_regions != NULL)
            CHECK(strcmp(sc_correspondence_decided_by(other_regions), "other answer") == 0,
                  "decided by %s", sc_correspondence_decided_by(other_regions));
    }
done:
    sc_correspondence_free(other_regions);
    sc_correspondence_free(regions);
    sc_surface_map_free(m);
    sc_pointwise_free(back);
    sc_pointwise_free(other);
    sc_pointwise_free(p);
    sc_params_free(params);
    free(map);
    free(other_map);
    sc_shape_free(a);
    sc_shape_free(b);
}

/* Bad landmarks: refused by the setter (NULL, too many) or when the job starts (out of
 * range, left out by the repairs, one vertex with two partners), with the pair named and
 * nothing written; no result accessor fails on a result without a verdict. */
static void test_landmark_errors(void) {
    sc_shape *a = figure("star5", 0), *b = figure("star5", 2), *loose = NULL;
    sc_params *params = NULL;
    sc_pointwise *p = NULL, *sentinel = (sc_pointwise *)&p;
    sc_correspondence *c = NULL, *csentinel = (sc_correspondence *)&c;
    size_t n = sc_shape_n_vertices(b), nt = sc_shape_n_triangles(b);
    uint32_t pairs[2 * (SC_MAX_LANDMARKS + 1)], *faces = malloc(3 * nt * sizeof *faces);
    double *vertices = malloc(3 * (n + 1) * sizeof *vertices);
    size_t i;
    for (i = 0; i < 2 * (SC_MAX_LANDMARKS + 1); i++)
        pairs[i] = (uint32_t)(i / 2);
    CHECK_STATUS(sc_params_new(&params), SC_STATUS_OK);
    CHECK_STATUS(sc_params_set_landmarks(NULL, pairs, 1), SC_STATUS_NULL_ARGUMENT);
    CHECK_STATUS(sc_params_set_landmarks(params, NULL, 2), SC_STATUS_NULL_ARGUMENT);
    CHECK_STATUS(sc_params_set_landmarks(params, pairs, SC_MAX_LANDMARKS + 1),
                 SC_STATUS_INVALID_PARAMETER);
    CHECK(strstr(sc_last_error(), "at most 100") != NULL, "message: %s", sc_last_error());
    CHECK(sc_params_n_landmarks(params) == 0, "nothing set by a failed call");
    CHECK_STATUS(sc_params_set_landmarks(params, pairs, SC_MAX_LANDMARKS), SC_STATUS_OK);
    CHECK(sc_params_n_landmarks(params) == SC_MAX_LANDMARKS, "the limit itself is accepted");
    CHECK_STATUS(sc_params_set_landmarks(params, NULL, 0), SC_STATUS_OK);
    CHECK(sc_params_n_landmarks(params) == 0, "0 pairs clear them");
    CHECK(sc_params_n_landmarks(NULL) == 0, "none for NULL");
    CHECK_STATUS(sc_params_landmarks(NULL, pairs, 2), SC_STATUS_NULL_ARGUMENT);

    /* Out of range on B: pair 2 named, refused before any work, nothing written. */
    pairs[0] = 1; pairs[1] = 1; pairs[2] = 2; pairs[3] = (uint32_t)n + 5;
    CHECK_STATUS(sc_params_set_landmarks(params, pairs, 2), SC_STATUS_OK);
    p = sentinel;
    CHECK_STATUS(sc_pointwise_map(a, b, params, NULL, NULL, &p), SC_STATUS_INVALID_PARAMETER);
    CHECK(strstr(sc_last_error(), "pair 2") != NULL && strstr(sc_last_error(), "landmarks"),
          "message: %s", sc_last_error());
    CHECK(p == sentinel, "nothing written on failure");
    c = csentinel;
    CHECK_STATUS(sc_match(a, b, params, NULL, NULL, &c), SC_STATUS_INVALID_PARAMETER);
    CHECK(strstr(sc_last_error(), "pair 2") != NULL, "message: %s", sc_last_error());
    CHECK(c == csentinel, "nothing written on failure");
    /* One vertex of A given two partners. */
    pairs[2] = 1; pairs[3] = 7;
    CHECK_STATUS(sc_params_set_landmarks(params, pairs, 2), SC_STATUS_OK);
    CHECK_STATUS(sc_pointwise_map(a, b, params, NULL, NULL, &p), SC_STATUS_INVALID_PARAMETER);
    CHECK(strstr(sc_last_error(), "contradict") != NULL, "message: %s", sc_last_error());
    /* A vertex no face uses (left out of the computation). */
    if (faces != NULL && vertices != NULL) {
        CHECK_STATUS(sc_shape_vertices(b, vertices, 3 * n), SC_STATUS_OK);
        CHECK_STATUS(sc_shape_triangles(b, faces, 3 * nt), SC_STATUS_OK);
        vertices[3 * n] = vertices[3 * n + 1] = vertices[3 * n + 2] = 0.0;
        CHECK_STATUS(sc_shape_new_mesh(vertices, n + 1, faces, nt, &loose), SC_STATUS_OK);
        pairs[0] = 3; pairs[1] = (uint32_t)n;
        CHECK_STATUS(sc_params_set_landmarks(params, pairs, 1), SC_STATUS_OK);
        CHECK_STATUS(sc_pointwise_map(a, loose, params, NULL, NULL, &p),
                     SC_STATUS_INVALID_PARAMETER);
        CHECK(strstr(sc_last_error(), "not used by the computation") != NULL, "message: %s",
              sc_last_error());
    }
    CHECK(p == sentinel, "nothing written on failure");

    /* NULL results: no name, no cost, no decision, no other answer. */
    CHECK(sc_pointwise_hypothesis(NULL, SC_ANSWER_CHOSEN) == NULL, "NULL pointwise");
    CHECK(sc_correspondence_hypothesis(NULL, SC_ANSWER_CHOSEN) == NULL, "NULL correspondence");
    CHECK(sc_pointwise_decided_by(NULL) == NULL && sc_correspondence_decided_by(NULL) == NULL,
          "no decision for NULL");
    CHECK(!sc_pointwise_placement_used(NULL) && !sc_correspondence_placement_used(NULL),
          "no placement for NULL");
    CHECK(sc_pointwise_taken_as(NULL, NULL) == NULL && isnan(sc_pointwise_covered_share(NULL)),
          "no partiality for NULL");
    CHECK(isnan(sc_pointwise_turn_degrees(NULL, 0)) && isnan(sc_correspondence_turn_degrees(NULL, 0)),
          "no turn for NULL");
    CHECK(isnan(sc_pointwise_hypothesis_cost(NULL, 0)) &&
              isnan(sc_correspondence_hypothesis_cost(NULL, 0)),
          "no cost for NULL");
    p = sentinel;
    CHECK_STATUS(sc_pointwise_other_answer(NULL, &p), SC_STATUS_NULL_ARGUMENT);
    CHECK(p == sentinel, "nothing written on failure");
    c = csentinel;
    CHECK_STATUS(sc_correspondence_other_answer(NULL, &c), SC_STATUS_NULL_ARGUMENT);
    CHECK(c == csentinel, "nothing written on failure");
    sc_shape_free(loose);
    sc_params_free(params);
    free(faces);
    free(vertices);
    sc_shape_free(a);
    sc_shape_free(b);
}

static const struct {
    const char *name;
    void (*run)(void);
} tests[] = {
    {"version", test_version},
    {"status_text", test_status_text},
    {"options", test_options},
    {"option_extremes", test_option_extremes},
    {"shape_errors", test_shape_errors},
    {"repairs", test_repairs},
    {"match_errors", test_match_errors},
    {"resource_limits", test_resource_limits},
    {"life_cycle", test_life_cycle},
    {"point_cloud", test_point_cloud},
    {"unverified_has_no_confidence", test_unverified_has_no_confidence},
    {"working", test_working},
    {"cancellation", test_cancellation},
    {"cancel_huge_restarts", test_cancel_huge_restarts},
    {"symmetry", test_symmetry},
    {"pointwise_options", test_pointwise_options},
    {"pointwise_errors", test_pointwise_errors},
    {"pointwise_permuted_copy", test_pointwise_permuted_copy},
    {"pointwise_cancellation", test_pointwise_cancellation},
    {"transfer", test_transfer},
    {"handles_in_use", test_handles_in_use},
    {"surface_map_shapes", test_surface_map_shapes},
    {"no_match_is_an_error", test_no_match_is_an_error},
    {"batch", test_batch},
    {"landmarks_and_other_answer", test_landmarks_and_other_answer},
    {"landmark_errors", test_landmark_errors},
    {"concurrency", test_concurrency},
};

/* `test_api` runs every test; `test_api NAME...` runs the named ones (tests/c/run.sh runs a
 * subset under valgrind); `test_api --list` prints the names. */
int main(int argc, char **argv) {
    const size_t n_tests = sizeof tests / sizeof tests[0];
    const char *q = getenv("SHAPECORR_TEST_QUICK");
    size_t t;
    int i;
    quick = q != NULL && strcmp(q, "1") == 0;
    if (argc == 2 && strcmp(argv[1], "--list") == 0) {
        for (t = 0; t < n_tests; t++)
            printf("%s\n", tests[t].name);
        return 0;
    }
    for (i = 1; i < argc; i++) {
        for (t = 0; t < n_tests && strcmp(argv[i], tests[t].name) != 0; t++)
            ;
        if (t == n_tests) {
            fprintf(stderr, "no test named %s (test_api --list names them)\n", argv[i]);
            return 2;
        }
    }
    for (t = 0; t < n_tests; t++) {
        bool wanted = argc == 1;
        for (i = 1; i < argc && !wanted; i++)
            wanted = strcmp(argv[i], tests[t].name) == 0;
        if (wanted)
            tests[t].run();
    }
    printf("%d checks, %d failures%s\n", checks, failures, quick ? " (quick)" : "");
    return failures == 0 ? 0 : 1;
}
