/* yproc - command-line front end of sw/hsr and sw/yproc.
 *   yproc hsr SCENE [--dump-llr FILE.json] [--dump-input FILE.json]
 *                   [--svg FILE.svg] [--stats] [--ops FILE] [--rebuild]
 * (--ops: incremental operations after the build, yproc_ops.c; --rebuild:
 *  then a full hsr_rebuild of the resulting MLR, for comparison)
 *   yproc scan SCENE -o OUTDIR [--mode M] [--no-aa] [--shading S] [--frames N]
 *                    [--cmd] [--tol T] [--capacity N] [--expect]
 *   yproc anim ANIMSCENE -o OUTDIR [scan options] [--full] [--lod-loop]
 *                    [--lod-predict] [--monitor-stdin] [--coherent]
 * (scan / anim: docs/yproc.md)
 * Reads the scene (and its OBJ files), applies viewing and perspective,
 * runs the exact incremental HSR and writes the requested outputs.
 * Errors are printed as "file:line: message"; the exit status is 1. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include "yproc_tools.h"

static const char USAGE[] =
    "usage: yproc hsr SCENE [--dump-llr FILE.json] [--dump-input FILE.json] [--svg FILE.svg]\n"
    "                 [--stats] [--ops FILE] [--rebuild]\n"
    "       yproc scan SCENE -o OUTDIR [--mode 640x480|640x485|1280x1024] [--no-aa]\n"
    "                  [--shading flat|gouraud|phong] [--frames N] [--cmd] [--tol T]\n"
    "                  [--capacity SLOTS] [--expect] [--no-degrade] [--lod L]\n"
    "       yproc anim ANIMSCENE -o OUTDIR [the scan options] [--full] [--lod-loop]\n"
    "                  [--lod-predict] [--monitor-stdin] [--coherent]\n"
    "       yproc read SCENE -o FILE.json\n"
    "       yproc serve SCENE --dir DIR\n"
    "\n"
    "hsr   exact hidden-surface removal of SCENE (docs/hsr.md)\n"
    "      --dump-llr F    the visible domains (LLR) as JSON     --dump-input F  the projected input faces\n"
    "      --svg F         the visible domains as an SVG picture --stats         face and domain counts\n"
    "      --ops F         incremental operations after the build (remove/move/add/opacity)\n"
    "      --rebuild       then a full rebuild of the result, for comparison\n"
    "scan  HSR, scan conversion and shading into r/g/b command streams in OUTDIR (docs/yproc.md)\n"
    "      --mode M        video mode (default 640x480)          --no-aa         no anti-aliasing\n"
    "      --shading S     flat, gouraud or phong                --frames N      render N times (timing)\n"
    "      --cmd           also write the commands as text       --tol T         fit tolerance (>= 0.01)\n"
    "      --capacity N    slots per line (>= 4; default: the mode's, Table 7.3)\n"
    "      --expect        also write the expected pixels\n"
    "      --no-degrade    no look-ahead degradation: a line over the capacity overflows\n"
    "      --lod L         every line at level of detail L (0..5; 5 = the options; docs/yproc.md 10)\n"
    "anim  an animation (.anim) through the incremental pipeline, frame by frame\n"
    "      --full          re-render every frame in full (the baseline); with --expect also each\n"
    "                      frame's expect.ppm and ideal.f64 (the exact shading)\n"
    "      --lod-loop      per-line level of detail from the previous frame's Load Monitor\n"
    "                      counts (model of rtl/ctrl/de_load_monitor.sv; implies --no-degrade)\n"
    "      --lod-predict   the loop, and before a frame is emitted every line over the capacity\n"
    "                      is lowered and re-scanned until it fits; a line that does not fit at\n"
    "                      level 0 makes the objects of .anim 'tessellation' statements on it\n"
    "                      coarser (implies --lod-loop)\n"
    "      --monitor-stdin the loop reads the monitor's record from stdin instead of its model:\n"
    "                      after each frame, 'monitor F' on stdout, then one line on stdin:\n"
    "                      F, H issued counts, H late flags (diffengine anim --lod-loop --rtl)\n"
    "      --coherent      keep the previous frame's colour functions where they still meet the\n"
    "                      tolerance, refit only the failing spans (docs/yproc.md 11)\n"
    "read  the scene and its OBJ/MTL files as read, as JSON (schema hsr-scene-1, docs/hsr.md):\n"
    "      what the Python reference renderer draws, so every format has one reader\n"
    "serve the scene held for the viewer (docs/viewer.md): one request a line on stdin (pick,\n"
    "      move, opacity, light, options, frame, info, quit), one JSON reply a line on stdout;\n"
    "      a frame's changed lines are written to DIR/r.de48, g.de48, b.de48\n"
    "\n"
    "Errors are printed as \"file:line: message\" with exit status 1; a bad command line exits 2.\n";

double yproc_clock_ms(clockid_t id)
{
    struct timespec t;
    clock_gettime(id, &t);
    return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

/* A help request anywhere on the line is answered on stdout with exit 0 (for scripts and
 * `--help` checks); a bad command line names what is wrong and exits 2. */
int yproc_usage_error(const char *what, const char *arg)
{
    if (what) fprintf(stderr, "yproc: %s%s%s%s\n", what, arg ? " '" : "", arg ? arg : "", arg ? "'" : "");
    fputs(USAGE, stderr);
    return 2;
}

static int read_main(int argc, char **argv)
{
    if (argc != 5 || strcmp(argv[3], "-o"))
        return yproc_usage_error(argc == 4 && !strcmp(argv[3], "-o") ? "missing value after '-o'"
                                 : "expected: yproc read SCENE -o FILE.json", NULL);
    char err[1024] = "";
    hsr_scene *sc;
    hsr_status st = hsr_scene_load(argv[2], &sc, err, sizeof err);
    if (st != HSR_OK) { fprintf(stderr, "%s\n", err[0] ? err : hsr_status_str(st)); return 1; }
    st = hsr_write_scene_json(argv[4], sc);
    if (st != HSR_OK) fprintf(stderr, "%s: cannot write (%s)\n", argv[4], hsr_status_str(st));
    hsr_scene_free(sc);
    return st == HSR_OK ? 0 : 1;
}

int main(int argc, char **argv)
{
    for (int i = 1; i < argc; i++)
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) { fputs(USAGE, stdout); return 0; }
    if (argc < 2) return yproc_usage_error("missing subcommand (hsr, scan, anim, read or serve)", NULL);
    if (strcmp(argv[1], "hsr") && strcmp(argv[1], "scan") && strcmp(argv[1], "anim") && strcmp(argv[1], "read")
        && strcmp(argv[1], "serve"))
        return yproc_usage_error("unknown subcommand", argv[1]);
    if (argc < 3) return yproc_usage_error("missing scene file after", argv[1]);
    if (!strcmp(argv[1], "read")) return read_main(argc, argv);
    if (!strcmp(argv[1], "serve")) return yproc_serve_main(argc, argv);
    if (strcmp(argv[1], "hsr")) return yproc_scan_main(argc, argv);
    const char *scene = argv[2], *json = NULL, *svg = NULL, *input = NULL, *ops = NULL;
    int stats = 0, rebuild = 0;
    for (int i = 3; i < argc; i++) {
        if (!strcmp(argv[i], "--dump-llr") && i + 1 < argc) json = argv[++i];
        else if (!strcmp(argv[i], "--dump-input") && i + 1 < argc) input = argv[++i];
        else if (!strcmp(argv[i], "--svg") && i + 1 < argc) svg = argv[++i];
        else if (!strcmp(argv[i], "--stats")) stats = 1;
        else if (!strcmp(argv[i], "--ops") && i + 1 < argc) ops = argv[++i];
        else if (!strcmp(argv[i], "--rebuild")) rebuild = 1;
        else if (i + 1 == argc && (!strcmp(argv[i], "--dump-llr") || !strcmp(argv[i], "--dump-input")
                                   || !strcmp(argv[i], "--svg") || !strcmp(argv[i], "--ops")))
            return yproc_usage_error("missing value after", argv[i]);
        else return yproc_usage_error("unknown option", argv[i]);
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
    int rc = ops ? yproc_apply_ops(h, ops, &shade) : 0;
    if (!rc && rebuild && (st = hsr_rebuild(h)) != HSR_OK) {
        fprintf(stderr, "%s: rebuild failed (%s)\n", scene, hsr_status_str(st)); rc = 1;
    }
    if (!rc && (ops || rebuild) && (st = hsr_check(h)) != HSR_OK) {
        fprintf(stderr, "%s: inconsistent LLR/MLR administration after the operations (%s)\n",
                ops ? ops : scene, hsr_status_str(st)); rc = 1;
    }
    if (rc) { free(shade); hsr_destroy(h); hsr_scene_free(sc); return rc; }
    if (json && (st = hsr_write_llr_json(json, h, sc)) != HSR_OK) {
        fprintf(stderr, "%s: cannot write (%s)\n", json, hsr_status_str(st)); rc = 1;
    }
    if (input && (st = hsr_write_input_json(input, h, sc)) != HSR_OK) {
        fprintf(stderr, "%s: cannot write (%s)\n", input, hsr_status_str(st)); rc = 1;
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
