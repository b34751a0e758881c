/* hsr_bench - benchmark entry points of sw/hsr (driven by diffengine bench hsr).
 *
 *   hsr_bench grid EXTENTS W SIZE NQ N1 [N2 ...]
 *       EXTENTS: text file, one "left bot right top" (integers) per line,
 *       window [0,W]x[0,W].  For every subdivision N an N x N Grid-List over
 *       the window is filled, then NQ x NQ query extents of SIZE x SIZE are
 *       placed on a regular grid of positions covering the window.  Prints per
 *       N: "grid N entries E empty_cells C overlaps O": list entries visited
 *       (hsr_gridlist_query's count, including the entry that stops a list),
 *       empty cells addressed (counted as memory accesses, as footnote 10 of
 *       section 5.3.3 does) and extents actually overlapping, summed over all
 *       queries, and mean_ratio: the mean over queries with at least one
 *       overlap of (entries + empty cells) / overlaps.  Also: cells = cells
 *       addressed; passed = entries with right+top >= Q.left+Q.bot (entries
 *       minus the ones that stop a list: what the sorted lists force any scan
 *       of those cells to visit); seed_entries / seed_empty / seed_mean_ratio
 *       = the same counts for the cell range of the loops of section 5.3.2
 *       started ceil((w_Q + w_max) m / X) columns before the one holding
 *       Q.right (rows likewise), a superset of ours.  Each query's entries are
 *       recounted from independent sorted copies of the cell lists and must
 *       equal hsr_gridlist_query's count (else exit 1).
 *   hsr_bench hsr SCENE [REPEAT]
 *       Builds the scene (projection + incremental HSR of every face, in
 *       order) REPEAT times; prints faces, visible domains, best seconds.
 *   hsr_bench stack steps|spets N [REPEAT] [reverse]
 *       N nested triangles (0,0),(s,0),(0,s), s = 2^18 (N-i)/N units,
 *       tri-steps: smaller ones nearer (all visible), tri-spets: larger ones
 *       nearer (one visible); added in order (or reversed).  Prints
 *       triangles, visible domains, best seconds.
 *   hsr_bench move SCENE_A SCENE_B K [REPEAT]
 *       SCENE_A and SCENE_B differ only in the last K faces (a small object
 *       moved).  Times (process CPU time) the full build of A, hsr_rebuild of A, and the
 *       incremental move of those K faces (K <= 64) to their B geometry and
 *       back, first with one hsr_move per face (move, move_back), then with
 *       one hsr_change_many for all K (move_many, move_many_back); checks
 *       after every move that every MLR id's visible area equals that of a
 *       full build of B (and after every move back, of A; 1e-9 relative) and
 *       that hsr_check passes.  Prints the best times of REPEAT rounds, the
 *       visible domains of the builds of A and B, after the first
 *       hsr_change_many (visible_moved) and after the last round's moves
 *       (visible_cycled, before its rebuild), and "check ok" or the mismatch.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "hsr.h"

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* CPU time of the process (move: one core's time, steady on a loaded machine) */
static double cpu_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static const char USAGE[] =
    "usage: hsr_bench grid EXTENTS W SIZE NQ N1 [N2 ...]\n"
    "       hsr_bench hsr SCENE [REPEAT]\n"
    "       hsr_bench stack steps|spets N [REPEAT] [reverse]\n"
    "       hsr_bench move SCENE_A SCENE_B K [REPEAT]\n"
    "grid: Grid-List efficiency (Table 5.2); hsr: full build time; stack: tri-steps/spets\n"
    "(Fig. 5.30); move: incremental move against a rebuild. Driven by the bench scripts.\n";

static int usage(void)
{
    fputs(USAGE, stderr);
    return 2;
}

static void count_cb(int id, void *ctx) { (void)id; (*(long *)ctx)++; }

/* ---- grid: Table 5.2 ------------------------------------------------ */
typedef struct { int cell; int64_t key; } cellkey;

static int cellkey_cmp(const void *a, const void *b)
{
    const cellkey *x = a, *y = b;
    if (x->cell != y->cell) return x->cell < y->cell ? -1 : 1;
    return x->key > y->key ? -1 : x->key < y->key;      /* decreasing key */
}

/* entries of one cell list (keys decreasing) a scan stopping at key < k visits:
 * those with key >= k (*ge) and, if the list goes on, the one that stops it */
static long cell_visits(const int64_t *keys, int n, int64_t k, long *ge)
{
    int lo = 0, hi = n;                 /* first index with key < k */
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (keys[mid] >= k) lo = mid + 1; else hi = mid;
    }
    *ge = lo;
    return lo + (lo < n);
}

static int cmd_grid(int argc, char **argv)
{
    if (argc < 7) return usage();
    FILE *f = fopen(argv[2], "r");
    if (!f) { perror(argv[2]); return 1; }
    int64_t W = atoll(argv[3]), Q = atoll(argv[4]);
    int nq = atoi(argv[5]);
    if (W < 1 || Q < 0 || nq < 1) { fprintf(stderr, "%s: bad W, SIZE or NQ\n", argv[0]); fclose(f); return 2; }
    int n = 0, cap = 1024, line = 0;
    hsr_extent *e = malloc(sizeof *e * (size_t)cap);
    char buf[256];
    while (e && fgets(buf, sizeof buf, f)) {
        long long l, b, r, t;
        line++;
        if (sscanf(buf, "%lld %lld %lld %lld", &l, &b, &r, &t) != 4 || r < l || t < b) {
            fprintf(stderr, "%s:%d: expected \"left bot right top\" with left <= right, bot <= top\n", argv[2], line);
            fclose(f); free(e); return 1;
        }
        if (n == cap) {
            cap *= 2;
            hsr_extent *ne = realloc(e, sizeof *e * (size_t)cap);
            if (!ne) { free(e); e = NULL; break; }
            e = ne;
        }
        e[n++] = (hsr_extent){l, b, r, t};
    }
    fclose(f);
    if (!e) { fprintf(stderr, "out of memory\n"); return 1; }
    int64_t wmax = 0, hmax = 0;
    for (int i = 0; i < n; i++) {
        if (e[i].right - e[i].left > wmax) wmax = e[i].right - e[i].left;
        if (e[i].top - e[i].bot > hmax) hmax = e[i].top - e[i].bot;
    }
    hsr_extent win = {0, 0, W, W};
    cellkey *ck = malloc(sizeof *ck * (size_t)(n ? n : 1));
    int64_t *keys = malloc(sizeof *keys * (size_t)(n ? n : 1));
    if (!ck || !keys) { free(e); free(ck); free(keys); fprintf(stderr, "out of memory\n"); return 1; }
    for (int a = 6; a < argc; a++) {
        int m = atoi(argv[a]);
        hsr_gridlist *g;
        if (hsr_gridlist_create(win, m, m, &g) != HSR_OK) { fprintf(stderr, "bad grid %d\n", m); return 1; }
        /* An independent copy of every cell's list (same cell rule as gridlist.c: the
         * cell of (left, bot), cells ceil(W/m) wide, border cells take what lies
         * outside), as sorted key arrays: it counts what a scan of any cell range
         * visits, so the real query's count can be checked and other ranges tried. */
        int64_t cw = (W + m - 1) / m, ch = cw;
#define COL(x) ((x) < 0 ? 0 : ((x) / cw >= m ? m - 1 : (int)((x) / cw)))
#define ROW(y) ((y) < 0 ? 0 : ((y) / ch >= m ? m - 1 : (int)((y) / ch)))
        int *start = calloc((size_t)m * (size_t)m + 1, sizeof(int));
        if (!start) { fprintf(stderr, "out of memory\n"); return 1; }
        for (int i = 0; i < n; i++) {
            if (hsr_gridlist_insert(g, i, e[i]) != HSR_OK) { fprintf(stderr, "insert failed\n"); return 1; }
            ck[i] = (cellkey){ROW(e[i].bot) * m + COL(e[i].left), e[i].right + e[i].top};
        }
        qsort(ck, (size_t)n, sizeof *ck, cellkey_cmp);
        for (int i = 0; i < n; i++) { keys[i] = ck[i].key; start[ck[i].cell + 1]++; }
        for (int c = 0; c < m * m; c++) start[c + 1] += start[c];
        /* seed: the loops of section 5.3.2 started ceil((w_Q + w_max) m / X) columns
         * (rows) before the one holding Q.right (Q.top), i.e. that many + 1 */
        int dc = (int)(((Q + wmax) * m + W - 1) / W), dr = (int)(((Q + hmax) * m + W - 1) / W);
        long long entries = 0, empty = 0, over = 0, nhit = 0, cells = 0, passed = 0;
        long long s_entries = 0, s_empty = 0;
        double ratio_sum = 0, s_ratio_sum = 0;   /* mean over queries with >= 1 overlap */
        double t0 = now();
        for (int qy = 0; qy < nq; qy++)
            for (int qx = 0; qx < nq; qx++) {
                int64_t cx = (int64_t)((qx + 0.5) * (double)W / nq), cy = (int64_t)((qy + 0.5) * (double)W / nq);
                hsr_extent q = {cx - Q / 2, cy - Q / 2, cx - Q / 2 + Q, cy - Q / 2 + Q};
                long hits = 0;
                long vis = hsr_gridlist_query(g, q, count_cb, &hits);
                int c0 = COL(q.left - wmax), c1 = COL(q.right), r0 = ROW(q.bot - hmax), r1 = ROW(q.top);
                int sc0 = c1 - dc < 0 ? 0 : c1 - dc, sr0 = r1 - dr < 0 ? 0 : r1 - dr;
                int64_t k = q.left + q.bot;
                long qv = 0, qe = 0, qp = 0, sv = 0, se = 0;
                for (int rr = sr0; rr <= r1; rr++)
                    for (int cc = sc0; cc <= c1; cc++) {
                        int c = rr * m + cc, len = start[c + 1] - start[c];
                        long ge, v = len ? cell_visits(keys + start[c], len, k, &ge) : 0;
                        int in = rr >= r0 && cc >= c0;
                        if (len) { sv += v; if (in) { qv += v; qp += ge; } }
                        else { se++; if (in) qe++; }
                    }
                if (qv != vis) {
                    fprintf(stderr, "grid %d: query (%lld,%lld) visited %ld entries, the sorted lists say %ld\n",
                            m, (long long)q.left, (long long)q.bot, vis, qv);
                    return 1;
                }
                entries += vis; over += hits; empty += qe; passed += qp;
                cells += (long long)(c1 - c0 + 1) * (r1 - r0 + 1);
                s_entries += sv; s_empty += se;
                if (hits > 0) {
                    ratio_sum += (double)(vis + qe) / (double)hits;
                    s_ratio_sum += (double)(sv + se) / (double)hits;
                    nhit++;
                }
            }
        double dt = now() - t0;
        printf("grid %d entries %lld empty_cells %lld overlaps %lld queries %d mean_ratio %.6f "
               "cells %lld passed %lld seed_entries %lld seed_empty %lld seed_mean_ratio %.6f seconds %.6f\n",
               m, entries, empty, over, nq * nq, nhit ? ratio_sum / (double)nhit : 0.0,
               cells, passed, s_entries, s_empty, nhit ? s_ratio_sum / (double)nhit : 0.0, dt);
        fflush(stdout);
        free(start);
        hsr_gridlist_free(g);
#undef COL
#undef ROW
    }
    free(ck); free(keys); free(e);
    return 0;
}

/* ---- hsr: full build of a scene ------------------------------------ */
static int count_visible(const hsr_ctx *h)
{
    int n = 0;
    for (int s = 0; s < hsr_llr_slots(h); s++) n += hsr_llr_get(h, s, NULL, NULL, NULL, NULL);
    return n;
}

static hsr_scene *load(const char *path)
{
    char err[1024] = "";
    hsr_scene *sc;
    hsr_status st = hsr_scene_load(path, &sc, err, sizeof err);
    if (st != HSR_OK) { fprintf(stderr, "%s\n", err[0] ? err : hsr_status_str(st)); return NULL; }
    return sc;
}

static int cmd_hsr(int argc, char **argv)
{
    if (argc < 3) return usage();
    int rep = argc > 3 ? atoi(argv[3]) : 1;
    hsr_scene *sc = load(argv[2]);
    if (!sc) return 1;
    double best = INFINITY;
    int vis = 0;
    for (int r = 0; r < rep; r++) {
        hsr_ctx *h; double *shade;
        double t0 = now();
        hsr_status st = hsr_scene_build(sc, &h, &shade);
        double dt = now() - t0;
        if (st != HSR_OK) { fprintf(stderr, "%s: %s\n", argv[2], hsr_status_str(st)); return 1; }
        if (dt < best) best = dt;
        vis = count_visible(h);
        free(shade);
        hsr_destroy(h);
    }
    printf("faces %d visible %d seconds %.6f\n", sc->nf, vis, best);
    hsr_scene_free(sc);
    return 0;
}

/* ---- stack: tri-steps / tri-spets (Fig 5.29) ----------------------- */
static int cmd_stack(int argc, char **argv)
{
    if (argc < 4) return usage();
    int steps = !strcmp(argv[2], "steps");
    if (!steps && strcmp(argv[2], "spets")) return usage();
    int n = atoi(argv[3]), rep = argc > 4 ? atoi(argv[4]) : 1;
    int rev = argc > 5 && !strcmp(argv[5], "reverse");
    if (n < 1) return usage();
    const int64_t SMAX = (int64_t)1 << 18;
    hsr_config cfg = {{0, 0, SMAX, SMAX}, 32, 32};
    double best = INFINITY;
    int vis = 0;
    for (int r = 0; r < rep; r++) {
        hsr_ctx *h;
        if (hsr_create(&cfg, &h) != HSR_OK) return 1;
        double t0 = now();
        for (int k = 0; k < n; k++) {
            int i = rev ? n - 1 - k : k;
            int64_t s = SMAX * (n - i) / n;      /* i = 0 is the largest */
            int64_t tri[6] = {0, 0, s, 0, 0, s};
            int len = 3, id;
            /* depth: tri-steps: larger = farther; tri-spets: larger = nearer */
            hsr_plane pl = {0, 0, steps ? (double)(n - i) : (double)i};
            if (hsr_add(h, tri, &len, 1, pl, 1.0, &id) != HSR_OK) { fprintf(stderr, "add failed\n"); return 1; }
        }
        double dt = now() - t0;
        if (dt < best) best = dt;
        vis = count_visible(h);
        hsr_destroy(h);
    }
    printf("triangles %d visible %d seconds %.6f\n", n, vis, best);
    return 0;
}

/* ---- move: incremental move of K faces vs a full rebuild ----------- */
static int to_rings(const hsr_domain *d, int64_t **xy, int **len, int *nr)
{
    double *dxy; int *dl, n;
    if (hsr_domain_rings(d, &dxy, &dl, &n) != HSR_OK) return 0;
    int tot = 0;
    for (int i = 0; i < n; i++) tot += dl[i];
    *xy = malloc(sizeof(int64_t) * 2 * (size_t)(tot + 1));
    for (int i = 0; i < 2 * tot; i++) {
        (*xy)[i] = llround(dxy[i]);
        if (fabs(dxy[i] - (double)(*xy)[i]) > 1e-6) { free(dxy); free(dl); return 0; }  /* not integer */
    }
    *len = dl; *nr = n;
    free(dxy);
    return 1;
}

typedef struct geom { int64_t *xy; int *len; int nr; hsr_plane pl; } geom;

static int grab(const hsr_ctx *h, int id, geom *g)
{
    const hsr_domain *d;
    if (!hsr_mlr_get(h, id, &d, &g->pl, NULL, NULL, NULL)) return 0;
    if (!to_rings(d, &g->xy, &g->len, &g->nr)) return 0;
    if (g->nr == 0) {               /* empty domain: one ring of length 0 */
        free(g->len); g->len = calloc(1, sizeof(int)); g->nr = 1;
    }
    return 1;
}

static void areas(const hsr_ctx *h, double *a, int n)
{
    for (int i = 0; i < n; i++) a[i] = 0;
    for (int s = 0; s < hsr_llr_slots(h); s++) {
        const hsr_domain *d; const int *par; int nv, np;
        if (hsr_llr_get(h, s, &d, &par, &nv, &np) && par[0] < n) a[par[0]] += hsr_domain_area(d);
    }
}

/* Moves faces n-K..n-1 to the geometry g: one hsr_move per face, or all in one
 * hsr_change_many (many); returns the seconds, or -1 on failure.  Compiled with
 * -DHSR_BENCH_BASELINE (against a libhsr without hsr_change_many) only per face. */
static double move_faces(hsr_ctx *h, int n, int K, const geom *g, int many)
{
    double t0 = cpu_now();
#ifdef HSR_BENCH_BASELINE   /* built against an older libhsr (diffengine bench hsr-incr) */
    (void)many;
#else
    if (many) {
        hsr_change c[64];
        for (int k = 0; k < K; k++)
            c[k] = (hsr_change){n - K + k, g[k].xy, g[k].len, g[k].nr, g[k].pl, -1};
        if (hsr_change_many(h, c, K) != HSR_OK) return -1;
    } else
#endif
    {
        for (int k = 0; k < K; k++)
            if (hsr_move(h, n - K + k, g[k].xy, g[k].len, g[k].nr, g[k].pl) != HSR_OK) return -1;
    }
    return cpu_now() - t0;
}

/* 1 if every MLR id's visible area in h equals want (a full build's) and
 * hsr_check passes, else prints the mismatch and returns 0 */
static int same_areas(const hsr_ctx *h, const double *want, double *got, int n, const char *what)
{
    int ok = 1;
    areas(h, got, n);
    for (int i = 0; i < n; i++)
        if (fabs(got[i] - want[i]) > 1e-9 * fmax(fabs(want[i]), 65536.0)) {
            printf("mismatch: MLR %d visible area after %s %.17g, full build %.17g\n", i, what, got[i], want[i]);
            ok = 0;
        }
    if (hsr_check(h) != HSR_OK) { printf("mismatch: hsr_check failed after %s\n", what); ok = 0; }
    return ok;
}

static int cmd_move(int argc, char **argv)
{
    if (argc < 5) return usage();
    int K = atoi(argv[4]), rep = argc > 5 ? atoi(argv[5]) : 3;
    hsr_scene *sa = load(argv[2]), *sb = load(argv[3]);
    if (!sa || !sb) return 1;
    if (sa->nf != sb->nf || K < 1 || K > sa->nf || K > 64 || rep < 1) {
        fprintf(stderr, "scenes differ in face count, or bad K (1..64) or REPEAT\n");
        return 1;
    }
    int n = sa->nf;
    hsr_ctx *ha, *hb; double *shade;
    double t_build = INFINITY, t_rebuild = INFINITY, t[4] = {INFINITY, INFINITY, INFINITY, INFINITY};
    for (int r = 0; r < rep; r++) {
        double t0 = cpu_now();
        if (hsr_scene_build(sa, &ha, &shade) != HSR_OK) return 1;
        double dt = cpu_now() - t0;
        if (dt < t_build) t_build = dt;
        free(shade);
        if (r + 1 < rep) hsr_destroy(ha);
    }
    if (hsr_scene_build(sb, &hb, &shade) != HSR_OK) return 1;
    free(shade);
    int vis_a = count_visible(ha), vis_b = count_visible(hb), vis_moved = 0, vis_cycled = 0;
    geom *ga = calloc((size_t)K, sizeof *ga), *gb = calloc((size_t)K, sizeof *gb);
    for (int k = 0; k < K; k++)
        if (!grab(ha, n - K + k, &ga[k]) || !grab(hb, n - K + k, &gb[k])) {
            fprintf(stderr, "cannot take face geometry\n"); return 1;
        }
    int ok = 1;
    double *aa = malloc(sizeof(double) * (size_t)n), *ab = malloc(sizeof(double) * (size_t)n),
           *a0 = malloc(sizeof(double) * (size_t)n);
    areas(hb, ab, n);
    areas(ha, a0, n);
    /* per round: per-face move and back, the same as one change_many each, a rebuild */
    for (int r = 0; r < rep; r++) {
#ifdef HSR_BENCH_BASELINE
        const int nmany = 1;   /* move_many and move_many_back print as inf */
#else
        const int nmany = 2;
#endif
        for (int many = 0; many < nmany; many++) {
            double dt = move_faces(ha, n, K, gb, many);
            if (dt < 0) { fprintf(stderr, "move failed\n"); return 1; }
            if (dt < t[2 * many]) t[2 * many] = dt;
            if (r == 0) {
                ok &= same_areas(ha, ab, aa, n, many ? "hsr_change_many" : "hsr_move");
                if (many || nmany == 1) vis_moved = count_visible(ha);
            }
            dt = move_faces(ha, n, K, ga, many);
            if (dt < 0) { fprintf(stderr, "move failed\n"); return 1; }
            if (dt < t[2 * many + 1]) t[2 * many + 1] = dt;
            if (r == 0) ok &= same_areas(ha, a0, aa, n, many ? "hsr_change_many back" : "hsr_move back");
        }
        if (r == rep - 1) vis_cycled = count_visible(ha);
        double t0 = cpu_now();
        if (hsr_rebuild(ha) != HSR_OK) return 1;
        double dt = cpu_now() - t0;
        if (dt < t_rebuild) t_rebuild = dt;
    }
    printf("faces %d moved %d visible_a %d visible_b %d build %.6f rebuild %.6f move %.6f move_back %.6f "
           "move_many %.6f move_many_back %.6f visible_moved %d visible_cycled %d check %s\n",
           n, K, vis_a, vis_b, t_build, t_rebuild, t[0], t[1], t[2], t[3], vis_moved, vis_cycled,
           ok ? "ok" : "MISMATCH");
    for (int k = 0; k < K; k++) { free(ga[k].xy); free(ga[k].len); free(gb[k].xy); free(gb[k].len); }
    free(ga); free(gb); free(aa); free(ab); free(a0);
    hsr_destroy(ha); hsr_destroy(hb);
    hsr_scene_free(sa); hsr_scene_free(sb);
    return ok ? 0 : 1;
}

int main(int argc, char **argv)
{
    for (int i = 1; i < argc; i++)
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) { fputs(USAGE, stdout); return 0; }
    if (argc < 2) return usage();
    if (!strcmp(argv[1], "grid")) return cmd_grid(argc, argv);
    if (!strcmp(argv[1], "hsr")) return cmd_hsr(argc, argv);
    if (!strcmp(argv[1], "stack")) return cmd_stack(argc, argv);
    if (!strcmp(argv[1], "move")) return cmd_move(argc, argv);
    return usage();
}
