/* Under an address-space limit (`ulimit -v`, set by tests/c/run.sh), sc_match and
 * sc_pointwise_map on two figures either run to the end or return
 * SC_STATUS_RESOURCE_LIMIT naming the limit: never an abort (docs/decisions.md,
 * "Address space"). Usage: memory_cap A.ply B.ply ok|limit */
#include <stdio.h>
#include <string.h>

#include "shapecorr.h"

static int expect(const char *what, sc_status status, const char *wanted) {
    int ok = strcmp(wanted, "ok") == 0
                 ? status == SC_STATUS_OK
                 : status == SC_STATUS_RESOURCE_LIMIT && strstr(sc_last_error(), "ulimit -v");
    printf("%s: status %d (%s)\n", what, (int)status,
           status == SC_STATUS_OK ? "ok" : sc_last_error());
    return ok ? 0 : 1;
}

int main(int argc, char **argv) {
    if (argc != 4) {
        fprintf(stderr, "usage: memory_cap A.ply B.ply ok|limit\n");
        return 2;
    }
    sc_shape *a = NULL, *b = NULL;
    if (sc_shape_read(argv[1], false, &a) != SC_STATUS_OK ||
        sc_shape_read(argv[2], false, &b) != SC_STATUS_OK) {
        fprintf(stderr, "reading the shapes: %s\n", sc_last_error());
        return 2;
    }
    sc_correspondence *c = NULL;
    int failures = expect("sc_match", sc_match(a, b, NULL, NULL, NULL, &c), argv[3]);
    sc_correspondence_free(c);
    sc_pointwise *p = NULL;
    failures += expect("sc_pointwise_map", sc_pointwise_map(a, b, NULL, NULL, NULL, &p), argv[3]);
    sc_pointwise_free(p);
    sc_shape_free(a);
    sc_shape_free(b);
    return failures == 0 ? 0 : 1;
}
