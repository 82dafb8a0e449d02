/*
 * The shortest path for a C/C++ developer: read two shapes with the library's own reader
 * (PLY, OFF, OBJ, XYZ), match them, print the region matches with their areas.
 *
 *   cc -std=c99 -Iinclude tests/c/example_match.c -Ltarget/release -lshapecorr \
 *      -Wl,-rpath,$PWD/target/release -o example_match
 *   ./example_match A.ply B.ply
 */
#include <stdio.h>
#include <stdlib.h>

#include "shapecorr.h"

static int fail(const char *what) {
    fprintf(stderr, "example_match: %s: %s\n", what, sc_last_error());
    return 1;
}

int main(int argc, char **argv) {
    sc_shape *a = NULL, *b = NULL;
    sc_correspondence *c = NULL;
    size_t n_matches, n_regions_a, n_regions_b, i;
    uint32_t *pairs;
    double *areas_a, *areas_b;
    int status = 0;
    if (argc != 3) {
        fprintf(stderr, "usage: %s A B   (PLY, OFF, OBJ or XYZ files)\n", argv[0]);
        return 2;
    }
    if (sc_shape_read(argv[1], false, &a) != SC_STATUS_OK)
        return fail(argv[1]);
    if (sc_shape_read(argv[2], false, &b) != SC_STATUS_OK) {
        sc_shape_free(a);
        return fail(argv[2]);
    }
    if (sc_match(a, b, NULL, NULL, NULL, &c) != SC_STATUS_OK) {
        status = fail("match");
        goto done;
    }
    n_matches = sc_correspondence_n_matches(c, SC_MATCHES_ONE_TO_ONE);
    n_regions_a = sc_correspondence_n_regions(c, SC_SIDE_A);
    n_regions_b = sc_correspondence_n_regions(c, SC_SIDE_B);
    pairs = malloc(2 * n_matches * sizeof *pairs + 1);
    areas_a = malloc(n_regions_a * sizeof *areas_a);
    areas_b = malloc(n_regions_b * sizeof *areas_b);
    if (sc_correspondence_matches(c, SC_MATCHES_ONE_TO_ONE, pairs, 2 * n_matches) ||
        sc_correspondence_region_areas(c, SC_SIDE_A, areas_a, n_regions_a) ||
        sc_correspondence_region_areas(c, SC_SIDE_B, areas_b, n_regions_b)) {
        status = fail("reading the result");
    } else {
        printf("%zu regions on A, %zu on B (k = %u); %zu one-to-one matches:\n", n_regions_a,
               n_regions_b, sc_correspondence_k(c), n_matches);
        for (i = 0; i < n_matches; i++)
            printf("  region %2u of A (%4.1f%% of its area) <-> region %2u of B (%4.1f%%)\n",
                   pairs[2 * i], 100.0 * areas_a[pairs[2 * i]], pairs[2 * i + 1],
                   100.0 * areas_b[pairs[2 * i + 1]]);
    }
    free(pairs);
    free(areas_a);
    free(areas_b);
done:
    sc_correspondence_free(c);
    sc_shape_free(a);
    sc_shape_free(b);
    return status;
}
