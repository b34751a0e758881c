/* yproc_scan.c - `yproc scan` and `yproc anim` (docs/yproc.md): scene ->
 * HSR -> y-processor -> r/g/b command streams, stats.json, summary line. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>
#include "yproc_tools.h"

/* process CPU time: the machine is shared, wall time would measure the
 * other processes too */
static double now_ms(void) { return yproc_clock_ms(CLOCK_PROCESS_CPUTIME_ID); }

typedef struct opts {
    const char *in, *out, *mode;
    yp_options yo;
    int frames, cmd, expect, full, width, height, mode_given;
    int lod_loop;        /* anim: per-line level of detail from the Load Monitor model */
    int coherent;        /* anim: temporally coherent fitting (yp_options.prev) */
    int lod_predict;     /* anim: and each line checked against the capacity before it is emitted */
    int monitor_stdin;   /* anim: the monitor's record per frame from stdin (the Verilated controller) */
    int lod_all;         /* scan: every line at this level of detail (-1: the options) */
} opts;

static int parse(int argc, char **argv, opts *o)
{
    memset(o, 0, sizeof *o);
    yp_options_default(&o->yo);
    o->in = argv[2]; o->mode = "640x480"; o->frames = 1; o->lod_all = -1;
    int cap = 0;
    for (int i = 3; i < argc; i++) {
        const char *a = argv[i];
        int has_value = i + 1 < argc;
        if (!strcmp(a, "--no-aa")) o->yo.aa = 0;
        else if (!strcmp(a, "--cmd")) o->cmd = 1;
        else if (!strcmp(a, "--expect")) o->expect = 1;
        else if (!strcmp(a, "--full")) o->full = 1;
        else if (!strcmp(a, "--no-degrade")) o->yo.no_degrade = 1;
        else if (!strcmp(a, "--lod-loop")) { o->lod_loop = 1; o->yo.no_degrade = 1; }
        else if (!strcmp(a, "--lod-predict")) { o->lod_loop = o->lod_predict = 1; o->yo.no_degrade = 1; }
        else if (!strcmp(a, "--monitor-stdin")) o->monitor_stdin = 1;
        else if (!strcmp(a, "--coherent")) o->coherent = o->yo.coherent = 1;
        else if (strcmp(a, "-o") && strcmp(a, "--mode") && strcmp(a, "--shading") && strcmp(a, "--frames")
                 && strcmp(a, "--tol") && strcmp(a, "--capacity") && strcmp(a, "--lod"))
            return yproc_usage_error("unknown option", a);
        else if (!has_value) return yproc_usage_error("missing value after", a);
        else if (!strcmp(a, "-o")) o->out = argv[++i];
        else if (!strcmp(a, "--mode")) { o->mode = argv[++i]; o->mode_given = 1; }
        else if (!strcmp(a, "--shading")) {
            const char *v = argv[++i];
            if (!strcmp(v, "flat")) o->yo.shading = YP_FLAT;
            else if (!strcmp(v, "gouraud")) o->yo.shading = YP_GOURAUD;
            else if (!strcmp(v, "phong")) o->yo.shading = YP_PHONG;
            else return yproc_usage_error("--shading takes flat, gouraud or phong, not", v);
        } else if (!strcmp(a, "--frames")) {
            o->frames = atoi(argv[++i]);
            if (o->frames < 1) return yproc_usage_error("--frames takes a count >= 1, not", argv[i]);
        } else if (!strcmp(a, "--lod")) {
            char *end;
            long v = strtol(argv[++i], &end, 10);
            if (*end || v < 0 || v > YP_LOD_MAX) return yproc_usage_error("--lod takes a level 0..5, not", argv[i]);
            o->lod_all = (int)v;
        } else if (!strcmp(a, "--tol")) {
            o->yo.tol = atof(argv[++i]);
            if (!(o->yo.tol >= 0.01)) return yproc_usage_error("--tol takes a number >= 0.01, not", argv[i]);
        } else {
            cap = atoi(argv[++i]);
            if (cap < 4) return yproc_usage_error("--capacity takes a slot count >= 4, not", argv[i]);
        }
    }
    if (!o->out) return yproc_usage_error("missing -o OUTDIR", NULL);
    if (o->monitor_stdin && !o->lod_loop) return yproc_usage_error("--monitor-stdin needs --lod-loop or --lod-predict", NULL);
    o->yo.capacity = yp_mode_capacity(o->mode, &o->width, &o->height);
    if (!o->yo.capacity) { fprintf(stderr, "yproc: unknown mode '%s' (640x480, 640x485, 1280x1024)\n", o->mode); return 1; }
    if (cap) o->yo.capacity = cap;
    return 0;
}

static int mkdir_p(const char *d)
{
    if (mkdir(d, 0777) == 0 || errno == EEXIST) return 0;
    fprintf(stderr, "%s: cannot create directory\n", d);
    return 1;
}

static const char *shading_name(yp_shading s) { return s == YP_FLAT ? "flat" : s == YP_GOURAUD ? "gouraud" : "phong"; }

typedef struct totals { long slots[3]; int maxslots[3], lines_degraded, lines_merged, lines_overflow, patterns_degraded; } totals;

static void frame_totals(const yp_frame *fr, totals *t)
{
    memset(t, 0, sizeof *t);
    for (int y = 0; y < fr->height; y++) {
        const yp_line_stats *s = &fr->st[y];
        int deg = 0, ov = 0, mg = 0;
        for (int c = 0; c < 3; c++) {
            t->slots[c] += s->slots[c];
            if (s->slots[c] > t->maxslots[c]) t->maxslots[c] = s->slots[c];
            deg |= s->degraded[c] > 0; ov |= s->overflow[c]; mg |= s->merged[c];
            t->patterns_degraded += s->degraded[c];
        }
        t->lines_degraded += deg; t->lines_overflow += ov; t->lines_merged += mg;
    }
}

static int write_streams(const yp_frame *fr, const char *dir, int cmd)
{
    static const char *nm = "rgb";
    char p[4096];
    for (int c = 0; c < 3; c++) {
        snprintf(p, sizeof p, "%s/%c.de48", dir, nm[c]);
        if (yp_write_de48(fr, c, p) != HSR_OK) { fprintf(stderr, "%s: cannot write\n", p); return 1; }
        if (cmd) {
            snprintf(p, sizeof p, "%s/%c.cmd", dir, nm[c]);
            if (yp_write_cmd(fr, c, p) != HSR_OK) { fprintf(stderr, "%s: cannot write\n", p); return 1; }
        }
    }
    return 0;
}

/* expect.ppm: the frame these commands give (16-bit binary PPM, maxval
 * 4095), ideal.f64: the exact target per pixel, float64 [3][H][W], LE */
static int write_expect(const yp_frame *fr, const char *dir)
{
    char p[4096];
    int W = fr->width, H = fr->height;
    uint16_t *pix = malloc(sizeof(uint16_t) * 3 * (size_t)W * (size_t)H);
    if (!pix) return 1;
    for (int c = 0; c < 3; c++)
        for (int y = 0; y < H; y++)
            if (yp_simulate_line(&fr->line[c * H + y], W, &pix[((size_t)c * H + y) * W]) != HSR_OK) {
                free(pix);
                return 1;
            }
    snprintf(p, sizeof p, "%s/expect.ppm", dir);
    FILE *f = fopen(p, "wb");
    if (!f) { free(pix); return 1; }
    fprintf(f, "P6\n%d %d\n4095\n", W, H);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int c = 0; c < 3; c++) {
                uint16_t v = pix[((size_t)c * H + y) * W + x];
                fputc(v >> 8, f); fputc(v & 255, f);
            }
    fclose(f);
    free(pix);
    snprintf(p, sizeof p, "%s/ideal.f64", dir);
    f = fopen(p, "wb");
    if (!f) return 1;
    fwrite(fr->ideal, sizeof(double), 3 * (size_t)W * (size_t)H, f);   /* host order (x86: LE) */
    fclose(f);
    return 0;
}

static void stats_frame_json(FILE *f, const yp_frame *fr, const opts *o, const char *indent)
{
    totals t;
    frame_totals(fr, &t);
    fprintf(f, "%s\"totals\": {\"slots\": [%ld, %ld, %ld], \"max_slots\": [%d, %d, %d], "
               "\"mean_slots\": [%.2f, %.2f, %.2f], \"lines_degraded\": %d, \"lines_merged\": %d, \"lines_overflow\": %d, "
               "\"patterns_degraded\": %d, \"evals\": {\"eval0\": %d, \"eval1\": %d, \"eval2\": %d, \"eval3\": %d}, "
               "\"knots\": %d, \"dis\": %d, \"partial_pixels\": %d, \"specular_evals\": %d}",
            indent, t.slots[0], t.slots[1], t.slots[2], t.maxslots[0], t.maxslots[1], t.maxslots[2],
            (double)t.slots[0] / fr->height, (double)t.slots[1] / fr->height, (double)t.slots[2] / fr->height,
            t.lines_degraded, t.lines_merged, t.lines_overflow, t.patterns_degraded, fr->n_eval[0], fr->n_eval[1], fr->n_eval[2],
            fr->n_eval[3], fr->n_knots, fr->n_dis, fr->n_partial, fr->n_spec);
    (void)o;
}

static int write_stats(const char *dir, const yp_frame *fr, const opts *o, const hsr_scene *sc,
                       double t_load, double t_hsr, double t_scan, double t_write, int nvis)
{
    char p[4096];
    snprintf(p, sizeof p, "%s/stats.json", dir);
    FILE *f = fopen(p, "w");
    if (!f) { fprintf(stderr, "%s: cannot write\n", p); return 1; }
    fprintf(f, "{\"format\": \"yproc-stats-1\", \"scene\": \"%s\", \"mode\": \"%s\", \"width\": %d, \"height\": %d,\n"
               " \"capacity\": %d, \"aa\": %s, \"shading\": \"%s\", \"tol\": %g, \"faces\": %d, \"llr_domains\": %d,\n"
               " \"times_ms\": {\"load\": %.3f, \"hsr\": %.3f, \"scan\": %.3f, \"write\": %.3f, \"frames_timed\": %d},\n ",
            sc->name, o->mode, fr->width, fr->height, o->yo.capacity, o->yo.aa ? "true" : "false",
            shading_name(o->yo.shading), o->yo.tol, sc->nf, nvis, t_load, t_hsr, t_scan, t_write, o->frames);
    stats_frame_json(f, fr, o, "");
    fprintf(f, ",\n \"lines\": [");
    for (int y = 0; y < fr->height; y++) {
        const yp_line_stats *s = &fr->st[y];
        fprintf(f, "%s\n  {\"y\": %d, \"cmds\": [%d, %d, %d], \"slots\": [%d, %d, %d], \"patterns\": %d, "
                   "\"partial\": %d, \"degraded\": [%d, %d, %d], \"merged\": [%d, %d, %d], \"overflow\": [%d, %d, %d]}",
                y ? "," : "", y, s->cmds[0], s->cmds[1], s->cmds[2], s->slots[0], s->slots[1], s->slots[2],
                s->patterns, s->partial, s->degraded[0], s->degraded[1], s->degraded[2],
                s->merged[0], s->merged[1], s->merged[2], s->overflow[0], s->overflow[1], s->overflow[2]);
    }
    fprintf(f, "\n]}\n");
    return fclose(f) == 0 ? 0 : 1;
}

static int scan_main(opts *o)
{
    char err[1024] = "";
    double t0 = now_ms();
    hsr_scene *sc;
    hsr_status st = hsr_scene_load(o->in, &sc, err, sizeof err);
    if (st != HSR_OK) { fprintf(stderr, "%s\n", err[0] ? err : hsr_status_str(st)); return 1; }
    /* --mode sets the raster (overriding the scene's `screen`); without it
     * the scene's screen is kept with the 640x480 line capacity */
    if (o->mode_given) { sc->width = o->width; sc->height = o->height; }
    yp_shader *sh;
    if ((st = yp_shader_new(sc, o->yo.shading, &sh, err, sizeof err)) != HSR_OK) {
        fprintf(stderr, "%s\n", err[0] ? err : hsr_status_str(st)); hsr_scene_free(sc); return 1;
    }
    double t1 = now_ms();
    hsr_ctx *h; double *shade;
    if ((st = hsr_scene_build(sc, &h, &shade)) != HSR_OK) {
        fprintf(stderr, "%s: %s\n", o->in, hsr_status_str(st)); yp_shader_free(sh); hsr_scene_free(sc); return 1;
    }
    free(shade);
    double t2 = now_ms();
    yp_frame *fr = NULL;
    unsigned char *lv = NULL;
    st = yp_frame_new(sc->width, sc->height, &fr);
    if (o->lod_all >= 0 && st == HSR_OK) {
        if (!(lv = malloc((size_t)sc->height))) st = HSR_ENOMEM;
        else { memset(lv, o->lod_all, (size_t)sc->height); o->yo.line_lod = lv; }
    }
    for (int k = 0; k < o->frames && st == HSR_OK; k++) st = yp_scan(sh, h, &o->yo, 0, sc->height, fr);
    double t3 = now_ms();
    int rc = 0;
    if (st != HSR_OK) { fprintf(stderr, "%s: scan conversion failed (%s)\n", o->in, hsr_status_str(st)); rc = 1; }
    int nvis = 0;
    for (int s = 0; s < hsr_llr_slots(h); s++) nvis += hsr_llr_get(h, s, NULL, NULL, NULL, NULL);
    if (!rc) rc = mkdir_p(o->out) || write_streams(fr, o->out, o->cmd) || (o->expect && write_expect(fr, o->out));
    double t4 = now_ms();
    if (!rc) rc = write_stats(o->out, fr, o, sc, t1 - t0, t2 - t1, (t3 - t2) / o->frames, t4 - t3, nvis);
    if (!rc) {
        totals t;
        frame_totals(fr, &t);
        printf("yproc scan %s: %dx%d %s %s, %d faces, %d LLR domains; slots/line r/g/b mean %.0f/%.0f/%.0f max %d/%d/%d "
               "of %d; lines degraded %d (merged %d), overflow %d; hsr %.1f ms, scan %.1f ms/frame, write %.1f ms\n",
               o->in, fr->width, fr->height, shading_name(o->yo.shading), o->yo.aa ? "aa" : "no-aa", sc->nf, nvis,
               (double)t.slots[0] / fr->height, (double)t.slots[1] / fr->height, (double)t.slots[2] / fr->height,
               t.maxslots[0], t.maxslots[1], t.maxslots[2], o->yo.capacity, t.lines_degraded, t.lines_merged, t.lines_overflow,
               t2 - t1, (t3 - t2) / o->frames, t4 - t3);
        fflush(stdout);
        if (t.lines_overflow)
            fprintf(stderr, "yproc: warning: %d line(s) exceed %d slots even as one spline per line (see stats.json)\n",
                    t.lines_overflow, o->yo.capacity);
    }
    yp_frame_free(fr); hsr_destroy(h); yp_shader_free(sh); hsr_scene_free(sc); free(lv);
    return rc;
}

/* ---- yproc anim ------------------------------------------------------ */
static void put_u16(FILE *f, unsigned v) { fputc((v >> 8) & 255, f); fputc(v & 255, f); }
static void put_u32(FILE *f, unsigned long v) { put_u16(f, (unsigned)(v >> 16) & 0xffff); put_u16(f, (unsigned)v & 0xffff); }

/* frame delta: "YPD1", u16 version 1, u16 frame, u16 width, u16 height;
 * then per colour r, g, b: u32 number of changed lines, and per changed
 * line: u16 line, u32 slots, slots x 6-byte words (the .de48 words of the
 * line's commands and its closing Refresh). */
static int write_delta(const char *path, int frame, const yp_frame *fr, char *const changed[3])
{
    FILE *f = fopen(path, "wb");
    if (!f) return 1;
    fwrite("YPD1", 1, 4, f);
    put_u16(f, 1); put_u16(f, (unsigned)frame); put_u16(f, (unsigned)fr->width); put_u16(f, (unsigned)fr->height);
    char tmp[] = "/tmp/yproc_line_XXXXXX";
    for (int c = 0; c < 3; c++) {
        unsigned long n = 0;
        for (int y = 0; y < fr->height; y++) n += changed[c][y] != 0;
        put_u32(f, n);
        for (int y = 0; y < fr->height; y++) {
            if (!changed[c][y]) continue;
            const yp_cmdlist *l = &fr->line[c * fr->height + y];
            put_u16(f, (unsigned)y); put_u32(f, (unsigned long)l->slots + 1);
            /* serialise through the .de48 writer of a one-line frame */
            yp_frame one = {fr->width, 1, (yp_cmdlist *)l, NULL, NULL, {0}, 0, 0, 0, 0};
            int fd = mkstemp(tmp);
            if (fd < 0) { fclose(f); return 1; }
            close(fd);
            if (yp_write_de48(&one, 0, tmp) != HSR_OK) { remove(tmp); fclose(f); return 1; }
            FILE *g = fopen(tmp, "rb");
            unsigned char buf[65536];
            size_t r;
            fseek(g, 8, SEEK_SET);
            while ((r = fread(buf, 1, sizeof buf, g)) > 0) fwrite(buf, 1, r, f);
            fclose(g); remove(tmp);
            snprintf(tmp, sizeof tmp, "/tmp/yproc_line_XXXXXX");
        }
    }
    return fclose(f) == 0 ? 0 : 1;
}

static int copy_lines(yp_cmdlist *dst, const yp_frame *fr)
{
    for (int i = 0; i < 3 * fr->height; i++) {
        yp_cmdlist_free(&dst[i]);
        for (int k = 0; k < fr->line[i].n; k++)
            if (yp_cmdlist_push(&dst[i], fr->line[i].c[k]) != HSR_OK) return 1;
    }
    return 0;
}

/* the frame as the Load Monitor records it (yp_lod_monitor, per line: the
 * largest count of the three colours, late if any is): overflowing lines, the mean
 * level of detail and, with the loop, the levels of the next frame after the update */
/* --monitor-stdin: "monitor F" on stdout, then one line on stdin: F, then H issued
 * counts and H late flags (0/1), as the Verilated controller's Load Monitor recorded
 * frame F (the largest count of the three colours, late if any was).  0 on success. */
static int read_monitor(int frame, int H, int *iss, int *late)
{
    printf("monitor %d\n", frame);
    fflush(stdout);
    char *line = NULL;
    size_t cap = 0;
    if (getline(&line, &cap, stdin) < 0) { free(line); fprintf(stderr, "yproc: frame %d: no monitor record on stdin\n", frame); return 1; }
    char *p = line, *end;
    long v = strtol(p, &end, 10);
    int bad = end == p || v != frame;
    for (int i = 0; i < 2 * H && !bad; i++) {
        p = end;
        v = strtol(p, &end, 10);
        if (end == p || v < 0 || (i >= H && v > 1)) bad = 1;
        else if (i < H) iss[i] = (int)v; else late[i - H] = (int)v;
    }
    free(line);
    if (bad) fprintf(stderr, "yproc: frame %d: bad monitor record on stdin (want: %d, %d issued counts, %d late flags)\n", frame, frame, H, H);
    return bad;
}

static int lod_stats(FILE *js, const yp_frame *fr, yp_lod *lod, int cap, int frame, int from_stdin, int lowered)
{
    int H = fr->height, ovl = 0, *iss = calloc(6 * (size_t)H + 1, sizeof(int));
    if (!iss) return 1;
    int *late = iss + H, *ic = iss + 2 * H, *lc = iss + 3 * H, *riss = iss + 4 * H, *rlate = iss + 5 * H;
    for (int c = 0; c < 3; c++) {
        for (int y = 0; y < H; y++) ic[y] = fr->st[y].slots[c];
        yp_lod_monitor(ic, H, cap, ic, lc);
        for (int y = 0; y < H; y++) { if (ic[y] > iss[y]) iss[y] = ic[y]; late[y] |= lc[y]; }
    }
    if (from_stdin) {
        /* the loop reads the controller's record; the model's is kept for comparison */
        if (read_monitor(frame, H, riss, rlate)) { free(iss); return 1; }
        int agree = 1;
        for (int y = 0; y < H; y++) agree &= riss[y] == iss[y] && rlate[y] == late[y];
        fprintf(js, ", \"monitor\": \"stdin\", \"model_agrees\": %d, \"model_overflow_lines\": ", agree);
        int mo = 0;
        for (int y = 0; y < H; y++) mo += late[y];
        fprintf(js, "%d", mo);
        memcpy(iss, riss, sizeof(int) * (size_t)H);
        memcpy(late, rlate, sizeof(int) * (size_t)H);
    }
    for (int y = 0; y < H; y++) ovl += late[y];
    fprintf(js, ", \"lowered_before_emit\": %d", lowered);
    const unsigned char *lv = yp_lod_levels(lod);
    double mean = YP_LOD_MAX;
    if (lv) { mean = 0; for (int y = 0; y < H; y++) mean += lv[y]; mean /= H; }
    fprintf(js, ", \"overflow_lines\": %d, \"mean_level\": %.4f, \"levels\": [", ovl, mean);
    for (int y = 0; y < H; y++) fprintf(js, "%s%d", y ? ", " : "", lv ? lv[y] : YP_LOD_MAX);
    fprintf(js, "], \"issued\": [");
    for (int y = 0; y < H; y++) fprintf(js, "%s%d", y ? ", " : "", iss[y]);
    fprintf(js, "]");
    /* the levels the frame was emitted at are printed above; the update sets the next's */
    if (lod) yp_lod_update(lod, iss, late);
    free(iss);
    return 0;
}

/* the frame's worst pixel: max over colours and pixels of |the array's 12-bit value
 * (yp_simulate_line) - the exact shading (fr->ideal)|, pixel units */
static double frame_max_err(const yp_frame *fr)
{
    int W = fr->width, H = fr->height;
    double mx = 0;
    uint16_t *pix = malloc(sizeof(uint16_t) * (size_t)W);
    if (!pix) return -1;
    for (int c = 0; c < 3; c++)
        for (int y = 0; y < H; y++) {
            if (yp_simulate_line(&fr->line[c * H + y], W, pix) != HSR_OK) { free(pix); return -1; }
            const double *id = &fr->ideal[((size_t)c * H + y) * W];
            for (int x = 0; x < W; x++) if (fabs(pix[x] - id[x]) > mx) mx = fabs(pix[x] - id[x]);
        }
    free(pix);
    return mx;
}

static int dcmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* how far the exact shading moved since the previous frame: median, 90th percentile and
 * max of |ideal - prev| over the pixels (and colours) whose exact value changed; prev then
 * takes the frame's values.  tmp: room for 3 W H doubles */
static void exact_change(const yp_frame *fr, double *prev, double *tmp, FILE *js)
{
    size_t n = 3 * (size_t)fr->width * (size_t)fr->height, k = 0;
    for (size_t i = 0; i < n; i++) {
        double d = fabs(fr->ideal[i] - prev[i]);
        if (d > 0) tmp[k++] = d;
        prev[i] = fr->ideal[i];
    }
    qsort(tmp, k, sizeof *tmp, dcmp);
    fprintf(js, ", \"exact_change\": {\"pixels\": %zu, \"median\": %.4f, \"p90\": %.4f, \"max\": %.4f}", k,
            k ? tmp[k / 2] : 0.0, k ? tmp[(size_t)(0.9 * (double)(k - 1))] : 0.0, k ? tmp[k - 1] : 0.0);
}

static void tess_json(FILE *js, yp_anim *an, int coarsened)
{
    yp_tess *t = yp_anim_tess(an);
    if (!t) return;
    fprintf(js, ", \"tess_coarsened\": %d, \"tess\": [", coarsened);
    for (int k = 0; k < yp_tess_count(t); k++) fprintf(js, "%s%d", k ? ", " : "", yp_tess_get(t, k));
    fprintf(js, "]");
}

static int anim_main(opts *o)
{
    char err[1024] = "", p[4096];
    yp_anim *an;
    hsr_status st = yp_anim_load(o->in, &an, err, sizeof err);
    if (st != HSR_OK) { fprintf(stderr, "%s\n", err[0] ? err : hsr_status_str(st)); return 1; }
    hsr_scene *sc = yp_anim_scene(an);
    if (o->mode_given) { sc->width = o->width; sc->height = o->height; }
    yp_shader *sh = NULL;
    hsr_ctx *h = NULL;
    yp_frame *fr = NULL;
    double *shade;
    int rc = 0, F = yp_anim_frames(an), W = sc->width, H = sc->height;
    yp_cmdlist *prev = calloc(3 * (size_t)H, sizeof(yp_cmdlist));
    int *chslots = calloc(3 * (size_t)H, sizeof(int));
    int *chcmds = calloc(3 * (size_t)H, sizeof(int));
    double *ideal_prev = malloc(sizeof(double) * 3 * (size_t)W * (size_t)H), *ideal_tmp = malloc(sizeof(double) * 3 * (size_t)W * (size_t)H);
    unsigned char *lod_prev = malloc((size_t)H + 1);
    char *changed[3];
    for (int c = 0; c < 3; c++) changed[c] = calloc((size_t)H, 1);
    if (!prev || !chslots || !chcmds || !ideal_prev || !ideal_tmp || !lod_prev || !changed[0] || !changed[1] || !changed[2]) { rc = 1; goto out; }
    memset(lod_prev, YP_LOD_MAX, (size_t)H);
    yp_lod *lod = NULL;
    if ((st = yp_anim_apply(an, 0, NULL, NULL, NULL, NULL)) != HSR_OK
        || (st = yp_shader_new(sc, o->yo.shading, &sh, err, sizeof err)) != HSR_OK
        || (st = yp_anim_apply(an, 0, NULL, sh, NULL, NULL)) != HSR_OK     /* point lights, textures */
        || (o->lod_loop && (st = yp_lod_new(H, o->yo.capacity, &lod)) != HSR_OK)) {
        fprintf(stderr, "%s\n", err[0] ? err : hsr_status_str(st)); rc = 1; goto out;
    }
    if (lod) o->yo.line_lod = yp_lod_levels(lod);
    double t0 = now_ms();
    if ((st = hsr_scene_build(sc, &h, &shade)) != HSR_OK) { fprintf(stderr, "%s: %s\n", o->in, hsr_status_str(st)); rc = 1; goto out; }
    free(shade);
    int lowered = 0, coarsened = 0, fy0 = 0, fy1 = H;
    if (yp_frame_new(W, H, &fr) != HSR_OK || yp_scan(sh, h, &o->yo, 0, H, fr) != HSR_OK
        || (o->lod_predict && yp_lod_fit_anim(lod, an, 0, h, sh, &o->yo, fr, &lowered, &coarsened, &fy0, &fy1) != HSR_OK)) { rc = 1; goto out; }
    if (lod) memcpy(lod_prev, yp_lod_levels(lod), (size_t)H);
    double t1 = now_ms();
    if (mkdir_p(o->out)) { rc = 1; goto out; }
    snprintf(p, sizeof p, "%s/frame000", o->out);
    if (mkdir_p(p) || write_streams(fr, p, o->cmd) || (o->expect && write_expect(fr, p)) || copy_lines(prev, fr)) { rc = 1; goto out; }
    memcpy(ideal_prev, fr->ideal, sizeof(double) * 3 * (size_t)W * (size_t)H);
    snprintf(p, sizeof p, "%s/anim_stats.json", o->out);
    FILE *js = fopen(p, "w");
    if (!js) { rc = 1; goto out; }
    fprintf(js, "{\"format\": \"yproc-anim-1\", \"anim\": \"%s\", \"frames\": %d, \"width\": %d, \"height\": %d, "
                "\"capacity\": %d, \"lod_loop\": %d, \"lod_predict\": %d, \"no_degrade\": %d, \"coherent\": %d, \"tol\": %g,\n"
                " \"frame\": [\n  {\"frame\": 0, \"full_ms\": %.3f, \"max_abs_err\": %.4f",
            o->in, F, W, H, o->yo.capacity, o->lod_loop, o->lod_predict, o->yo.no_degrade, o->coherent, o->yo.tol, t1 - t0,
            frame_max_err(fr));
    tess_json(js, an, coarsened);
    for (int k = 0; k < yp_tess_count(yp_anim_tess(an)); k++) {
        /* faces of each version (the scene's obj statements of the clustered meshes) */
        fprintf(js, "%s[", k ? ", " : ", \"tess_faces\": [");
        for (int v = 0; v < yp_tess_versions(yp_anim_tess(an), k); v++) {
            int nfo = 0, ob = yp_tess_obj(yp_anim_tess(an), k, v);
            for (int fi = 0; fi < sc->nf; fi++) nfo += sc->f[fi].obj == ob;
            fprintf(js, "%s%d", v ? ", " : "", nfo);
        }
        fprintf(js, "]%s", k + 1 == yp_tess_count(yp_anim_tess(an)) ? "]" : "");
    }
    if (lod_stats(js, fr, lod, o->yo.capacity, 0, o->monitor_stdin, lowered)) { rc = 1; fclose(js); goto out; }
    fprintf(js, "}");
    double sum_inc = 0, sum_full = 0, sum_inc_scan = 0, sum_full_scan = 0;
    long sum_changed = 0;
    int mismatches = 0, degraded_lines = 0;
    for (int f = 1; f < F && !rc; f++) {
        int y0, y1;
        double a0 = now_ms();
        /* tessellation: an object whose lines are all back at full quality tries its finer
         * mesh (the check below makes it coarser again if a line then does not fit) */
        if (o->lod_predict && yp_anim_tess(an)) yp_tess_refine(yp_anim_tess(an), sc, h, yp_lod_levels(lod), f);
        st = yp_anim_apply(an, f, h, sh, &y0, &y1);
        /* lines whose level of detail changed are re-scanned too */
        for (int y = 0; lod && y < H; y++)
            if (lod_prev[y] != yp_lod_levels(lod)[y]) { if (y0 == y1) { y0 = y; y1 = y + 1; } if (y < y0) y0 = y; if (y + 1 > y1) y1 = y + 1; }
        if (lod) memcpy(lod_prev, yp_lod_levels(lod), (size_t)H);
        if (o->coherent) o->yo.prev = prev;          /* the frame before this one */
        double am = now_ms();
        if (st == HSR_OK) st = yp_scan(sh, h, &o->yo, y0, y1, fr);
        /* the y-processor's own check: lines over the capacity lowered before they are emitted */
        lowered = coarsened = 0;
        if (st == HSR_OK && o->lod_predict) {
            st = yp_lod_fit_anim(lod, an, f, h, sh, &o->yo, fr, &lowered, &coarsened, &y0, &y1);
            memcpy(lod_prev, yp_lod_levels(lod), (size_t)H);
        }
        double a1 = now_ms();
        if (st != HSR_OK) { fprintf(stderr, "%s: frame %d: %s\n", o->in, f, hsr_status_str(st)); rc = 1; break; }
        int nch[3] = {0, 0, 0};
        for (int c = 0; c < 3; c++)
            for (int y = 0; y < H; y++) {
                changed[c][y] = y >= y0 && y < y1 && !yp_cmdlist_equal(&fr->line[c * H + y], &prev[c * H + y]);
                nch[c] += changed[c][y];
                /* instructions of the line that the delta really changes (LCS of the commands) */
                chcmds[c * H + y] = 0;
                chslots[c * H + y] = changed[c][y] ? yp_cmdlist_changed(&prev[c * H + y], &fr->line[c * H + y], &chcmds[c * H + y]) : 0;
            }
        snprintf(p, sizeof p, "%s/frame%03d.delta", o->out, f);
        if (write_delta(p, f, fr, changed)) { rc = 1; break; }
        double a2 = now_ms();
        /* the same frame from scratch: HSR rebuild + every line */
        double b0 = now_ms();
        hsr_ctx *hf = NULL;
        yp_frame *ff = NULL;
        st = hsr_scene_build(sc, &hf, &shade);
        double bm = now_ms();
        if (st == HSR_OK) { free(shade); st = yp_frame_new(W, H, &ff); }
        if (st == HSR_OK) st = yp_scan(sh, hf, &o->yo, 0, H, ff);
        double b1 = now_ms();
        int diff = 0, deg = 0;
        for (int i = 0; st == HSR_OK && i < 3 * H; i++) diff += !yp_cmdlist_equal(&ff->line[i], &fr->line[i]);
        for (int y = 0; y < H; y++) deg += fr->st[y].degraded[0] || fr->st[y].degraded[1] || fr->st[y].degraded[2];
        mismatches += diff != 0;
        degraded_lines += deg;
        if (st == HSR_OK && o->full) {
            snprintf(p, sizeof p, "%s/frame%03d", o->out, f);
            if (mkdir_p(p) || write_streams(ff, p, o->cmd) || (o->expect && write_expect(ff, p))) rc = 1;
        }
        yp_frame_free(ff); hsr_destroy(hf);
        if (st != HSR_OK || copy_lines(prev, fr)) { rc = 1; break; }
        sum_inc += a1 - a0; sum_full += b1 - b0; sum_changed += nch[0] + nch[1] + nch[2];
        sum_inc_scan += a1 - am; sum_full_scan += b1 - bm;
        fprintf(js, ",\n  {\"frame\": %d, \"rescanned_lines\": [%d, %d], \"changed_lines\": [%d, %d, %d], "
                    "\"incremental_ms\": %.3f, \"incremental_hsr_ms\": %.3f, \"incremental_scan_ms\": %.3f, "
                    "\"delta_write_ms\": %.3f, \"full_ms\": %.3f, \"full_hsr_ms\": %.3f, \"full_scan_ms\": %.3f, "
                    "\"lines_differing_from_full\": %d, \"lines_degraded\": %d, \"max_abs_err\": %.4f",
                f, y0, y1, nch[0], nch[1], nch[2], a1 - a0, am - a0, a1 - am, a2 - a1, b1 - b0, bm - b0, b1 - bm, diff, deg,
                frame_max_err(fr));
        fprintf(js, ", \"changed_slots\": [");
        for (int c = 0; c < 3; c++)
            for (int y = 0; y < H; y++) fprintf(js, "%s%s%d%s", y ? "" : c ? ", [" : "[", y ? ", " : "", chslots[c * H + y], y == H - 1 ? "]" : "");
        fprintf(js, "]");
        exact_change(fr, ideal_prev, ideal_tmp, js);
        fprintf(js, ", \"changed_cmds\": [");
        for (int c = 0; c < 3; c++)
            for (int y = 0; y < H; y++) fprintf(js, "%s%s%d%s", y ? "" : c ? ", [" : "[", y ? ", " : "", chcmds[c * H + y], y == H - 1 ? "]" : "");
        fprintf(js, "]");
        tess_json(js, an, coarsened);
        if (lod_stats(js, fr, lod, o->yo.capacity, f, o->monitor_stdin, lowered)) { rc = 1; break; }
        fprintf(js, "}");
        printf("frame %3d: lines %3d..%3d rescanned, changed r/g/b %d/%d/%d; incremental %.1f ms (hsr %.1f + scan %.1f), "
               "full %.1f ms (hsr %.1f + scan %.1f)%s\n", f, y0, y1, nch[0], nch[1], nch[2], a1 - a0, am - a0, a1 - am,
               b1 - b0, bm - b0, b1 - bm, diff ? " MISMATCH with full re-render" : "");
    }
    int nf1 = F > 1 ? F - 1 : 1;
    fprintf(js, "\n ],\n \"mean_incremental_ms\": %.3f, \"mean_incremental_scan_ms\": %.3f, \"mean_full_ms\": %.3f, "
                "\"mean_full_scan_ms\": %.3f, \"mean_changed_lines\": %.2f, \"frames_differing_from_full\": %d}\n",
            sum_inc / nf1, sum_inc_scan / nf1, sum_full / nf1, sum_full_scan / nf1, sum_changed / (3.0 * nf1), mismatches);
    fclose(js);
    if (!rc) {
        printf("yproc anim %s: %d frames %dx%d, changed lines/frame %.1f of %d (x3 colours), incremental %.1f ms/frame "
               "(scan %.1f), full %.1f ms/frame (scan %.1f), CPU time; frames differing from a full re-render: %d, "
               "degraded lines %d\n", o->in, F, W, H, sum_changed / (3.0 * nf1), H, sum_inc / nf1, sum_inc_scan / nf1,
               sum_full / nf1, sum_full_scan / nf1, mismatches, degraded_lines);
        if (mismatches) rc = 1;
    }
out:
    if (prev) for (int i = 0; i < 3 * H; i++) yp_cmdlist_free(&prev[i]);
    free(prev); free(chslots); free(chcmds); free(ideal_prev); free(ideal_tmp); free(lod_prev); yp_lod_free(lod);
    for (int c = 0; c < 3; c++) free(changed[c]);
    yp_frame_free(fr); hsr_destroy(h); yp_shader_free(sh); yp_anim_free(an);
    return rc;
}

int yproc_scan_main(int argc, char **argv)
{
    opts o;
    int r = parse(argc, argv, &o);
    if (r) return r;
    if (!strcmp(argv[1], "scan")) return scan_main(&o);
    return anim_main(&o);
}
