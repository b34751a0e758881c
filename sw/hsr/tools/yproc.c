/* yproc - command-line front end of sw/hsr.
 *   yproc hsr SCENE [--dump-llr FILE.json] [--svg FILE.svg] [--stats]
 * Reads the scene (and its OBJ files), applies viewing and perspective,
 * runs the exact incremental HSR and writes the requested outputs.
 * Errors are printed as "file:line: message"; the exit status is 1. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "hsr.h"

static int usage(void)
{
    fprintf(stderr, "usage: yproc hsr SCENE [--dump-llr FILE.json] [--svg FILE.svg] [--stats]\n");
    return 2;
}

int main(int argc, char **argv)
{
    if (argc < 3 || strcmp(argv[1], "hsr")) return usage();
    const char *scene = argv[2], *json = NULL, *svg = NULL;
    int stats = 0;
    for (int i = 3; i < argc; i++) {
        if (!strcmp(argv[i], "--dump-llr") && i + 1 < argc) json = argv[++i];
        else if (!strcmp(argv[i], "--svg") && i + 1 < argc) svg = argv[++i];
        else if (!strcmp(argv[i], "--stats")) stats = 1;
        else return usage();
    }
    char err[1024] = "";
    hsr_scene *sc;
    hsr_status st = hsr_scene_load(scene, &sc, err, sizeof err);
    if (st != HSR_OK) { fprintf(stderr, "%s\n", err[0] ? err : hsr_status_str(st)); return 1; }
    hsr_ctx *h;
    double *shade;
    st = hsr_scene_build(sc, &h, &shade);
    if (st != HSR_OK) {
        fprintf(stderr, "%s: %s\n", scene, hsr_status_str(st));
        hsr_scene_free(sc);
        return 1;
    }
    int rc = 0;
    if (json && (st = hsr_write_llr_json(json, h, sc)) != HSR_OK) {
        fprintf(stderr, "%s: cannot write (%s)\n", json, hsr_status_str(st)); rc = 1;
    }
    if (svg && (st = hsr_write_svg(svg, h, sc, shade)) != HSR_OK) {
        fprintf(stderr, "%s: cannot write (%s)\n", svg, hsr_status_str(st)); rc = 1;
    }
    if (stats) {
        int n = 0;
        for (int s = 0; s < hsr_llr_slots(h); s++) n += hsr_llr_get(h, s, NULL, NULL, NULL, NULL);
        printf("faces %d, visible domains %d\n", sc->nf, n);
    }
    free(shade);
    hsr_destroy(h);
    hsr_scene_free(sc);
    return rc;
}
