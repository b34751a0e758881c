/* test_props.c - seeded random scenes: LLR domains pairwise disjoint,
 * union of LLR == union of input, incremental sequences == full rebuild.
 * Every run prints its seed; replay with SEED=<n>. */
#include <stdlib.h>
#include <string.h>
#include "t.h"

static void rand_poly(unsigned long long *s, int64_t *xy, int *n)
{
    int64_t cx = 200 + (int64_t)(t_rand(s) % 3600), cy = 200 + (int64_t)(t_rand(s) % 3600);
    int64_t r = 50 + (int64_t)(t_rand(s) % 600);
    *n = 3 + (int)(t_rand(s) % 3);
    for (int i = 0; i < *n; i++) {
        xy[2 * i] = cx - r + (int64_t)(t_rand(s) % (unsigned)(2 * r));
        xy[2 * i + 1] = cy - r + (int64_t)(t_rand(s) % (unsigned)(2 * r));
        if (t_rand(s) % 8 == 0 && i > 0) xy[2 * i] = xy[2 * i - 2];    /* vertical edges */
        if (t_rand(s) % 8 == 0 && i > 0) xy[2 * i + 1] = xy[2 * i - 1]; /* horizontal edges */
    }
}

static hsr_plane rand_plane(unsigned long long *s)
{
    hsr_plane p = {0, 0, (double)(t_rand(s) % 1000)};
    if (t_rand(s) % 3 == 0) {   /* tilted: interpenetration happens */
        p.a = ((double)(t_rand(s) % 2001) - 1000) / 1000.0;
        p.b = ((double)(t_rand(s) % 2001) - 1000) / 1000.0;
    }
    return p;
}

static double rand_opacity(unsigned long long *s) { return t_rand(s) % 4 == 0 ? 0.5 : 1.0; }

/* union of all present MLR input domains / of all LLR domains */
static hsr_domain *union_of(const hsr_ctx *h, int llr)
{
    hsr_domain *u = NULL;
    hsr_domain_from_rings(NULL, NULL, 0, &u);
    int n = llr ? hsr_llr_slots(h) : hsr_mlr_slots(h);
    for (int i = 0; i < n; i++) {
        const hsr_domain *d;
        int ok = llr ? hsr_llr_get(h, i, &d, NULL, NULL, NULL) : hsr_mlr_get(h, i, &d, NULL, NULL, NULL, NULL);
        if (!ok) continue;
        hsr_domain *v = NULL;
        if (hsr_domain_boolean(u, d, HSR_UNION, &v) != HSR_OK) { hsr_domain_free(u); return NULL; }
        hsr_domain_free(u);
        u = v;
    }
    return u;
}

static int llr_pairwise_disjoint(const hsr_ctx *h)
{
    int n = hsr_llr_slots(h);
    for (int i = 0; i < n; i++) {
        const hsr_domain *a;
        if (!hsr_llr_get(h, i, &a, NULL, NULL, NULL)) continue;
        for (int j = i + 1; j < n; j++) {
            const hsr_domain *b;
            if (!hsr_llr_get(h, j, &b, NULL, NULL, NULL)) continue;
            if (!hsr_extent_overlap(hsr_domain_extent(a), hsr_domain_extent(b))) continue;
            hsr_domain *x = NULL;
            if (hsr_domain_boolean(a, b, HSR_INTERSECT, &x) != HSR_OK) return 0;
            int empty = hsr_domain_is_empty(x);
            hsr_domain_free(x);
            if (!empty) return 0;
        }
    }
    return 1;
}

/* area per visible prefix (the ordered parents up to the first opaque) */
typedef struct sig { int key[8]; int nk; double area; } sig;
static int sig_collect(const hsr_ctx *h, sig *out, int cap)
{
    int m = 0;
    for (int s = 0; s < hsr_llr_slots(h); s++) {
        const hsr_domain *d; const int *par; int nv, np;
        if (!hsr_llr_get(h, s, &d, &par, &nv, &np)) continue;
        int k = nv < 8 ? nv : 8, f = -1;
        for (int i = 0; i < m && f < 0; i++)
            if (out[i].nk == k && !memcmp(out[i].key, par, sizeof(int) * (size_t)k)) f = i;
        if (f < 0) {
            if (m == cap) return -1;
            f = m++;
            memcpy(out[f].key, par, sizeof(int) * (size_t)k);
            out[f].nk = k; out[f].area = 0;
        }
        out[f].area += hsr_domain_area(d);
    }
    return m;
}

static int sig_equal(const sig *a, int na, const sig *b, int nb, double tol)
{
    for (int pass = 0; pass < 2; pass++) {
        const sig *x = pass ? b : a, *y = pass ? a : b;
        int nx = pass ? nb : na, ny = pass ? na : nb;
        for (int i = 0; i < nx; i++) {
            double other = 0;
            for (int j = 0; j < ny; j++)
                if (y[j].nk == x[i].nk && !memcmp(y[j].key, x[i].key, sizeof(int) * (size_t)x[i].nk)) other = y[j].area;
            if (fabs(other - x[i].area) > tol) {
                fprintf(stderr, "  prefix [%d..] (len %d): %.6f vs %.6f\n", x[i].key[0], x[i].nk, x[i].area, other);
                return 0;
            }
        }
    }
    return 1;
}

static void check_invariants(const hsr_ctx *h, unsigned long long seed)
{
    CHECK(hsr_check(h) == HSR_OK);
    CHECK(llr_pairwise_disjoint(h));
    hsr_domain *ui = union_of(h, 0), *ul = union_of(h, 1), *x = NULL;
    CHECK(ui && ul && hsr_domain_boolean(ui, ul, HSR_XOR, &x) == HSR_OK);
    CHECK(hsr_domain_is_empty(x));
    double a = hsr_domain_area(ui);
    CHECK(fabs(t_llr_total_area(h) - a) <= 1e-9 * (1 + a));
    if (t_failed_now) fprintf(stderr, "  (seed=%llu)\n", seed);
    hsr_domain_free(ui); hsr_domain_free(ul); hsr_domain_free(x);
}

/* many: a fifth kind of step, hsr_change_many of 2..5 distinct present ids (some
 * moved, some given a new opacity, some both) */
static void run_scene(unsigned long long seed, int n, int ops, int many)
{
    unsigned long long s = seed;
    hsr_ctx *h = t_ctx();
    int64_t xy[12];
    int len;
    for (int i = 0; i < n; i++) {
        rand_poly(&s, xy, &len);
        int id;
        CHECK(hsr_add(h, xy, &len, 1, rand_plane(&s), rand_opacity(&s), &id) == HSR_OK);
    }
    check_invariants(h, seed);
    for (int k = 0; k < ops; k++) {
        int id = (int)(t_rand(&s) % (unsigned)hsr_mlr_slots(h)), op = (int)(t_rand(&s) % (many ? 5u : 4u));
        if (!hsr_mlr_get(h, id, NULL, NULL, NULL, NULL, NULL)) op = 3;
        if (op == 4) {
            hsr_change c[5];
            int64_t cxy[5][12];
            int clen[5], nc = 0, want = 2 + (int)(t_rand(&s) % 4);
            for (int tries = 0; tries < 40 && nc < want; tries++) {
                int j = (int)(t_rand(&s) % (unsigned)hsr_mlr_slots(h)), dup = 0;
                for (int i = 0; i < nc; i++) dup |= c[i].id == j;
                if (dup || !hsr_mlr_get(h, j, NULL, NULL, NULL, NULL, NULL)) continue;
                int kind = (int)(t_rand(&s) % 3);   /* 0 move, 1 opacity, 2 both */
                c[nc] = (hsr_change){j, NULL, NULL, 0, {0, 0, 0}, kind ? rand_opacity(&s) : -1};
                if (kind != 1) {
                    rand_poly(&s, cxy[nc], &clen[nc]);
                    c[nc].xy = cxy[nc]; c[nc].ring_len = &clen[nc]; c[nc].nrings = 1;
                    c[nc].plane = rand_plane(&s);
                }
                nc++;
            }
            CHECK(hsr_change_many(h, c, nc) == HSR_OK);
        } else if (op == 0) CHECK(hsr_remove(h, id) == HSR_OK);
        else if (op == 1) {
            rand_poly(&s, xy, &len);
            CHECK(hsr_move(h, id, xy, &len, 1, rand_plane(&s)) == HSR_OK);
        } else if (op == 2) CHECK(hsr_set_opacity(h, id, rand_opacity(&s)) == HSR_OK);
        else {
            rand_poly(&s, xy, &len);
            CHECK(hsr_add(h, xy, &len, 1, rand_plane(&s), rand_opacity(&s), &id) == HSR_OK);
        }
    }
    check_invariants(h, seed);
    static sig a[4096], b[4096];
    int na = sig_collect(h, a, 4096);
    CHECK(hsr_rebuild(h) == HSR_OK);
    check_invariants(h, seed);
    int nb = sig_collect(h, b, 4096);
    double tot = t_llr_total_area(h);
    CHECK(na >= 0 && nb >= 0 && sig_equal(a, na, b, nb, 1e-9 * (1 + tot)));
    if (t_failed_now) fprintf(stderr, "  (seed=%llu)\n", seed);
    hsr_destroy(h);
}

/* runs scenes base, base+1, ... (SEED=<n> replaces base): scene r has n0 + r * dn
 * domains, then ops steps */
static void run_seeds(const char *what, unsigned long long base, int runs, int n0, int dn, int ops, int many)
{
    if (getenv("SEED")) base = strtoull(getenv("SEED"), NULL, 10);
    printf("     %s: base seed=%llu, %d scenes\n", what, base, runs);
    for (int r = 0; r < runs && !t_failed_now; r++) run_scene(base + (unsigned long long)r, n0 + r * dn, ops, many);
}

static void test_random_scenes_disjoint_union_and_rebuild(void)
{
    run_seeds("random scenes", 20240601, t_quick ? 4 : 20, 25, 2, 20, 0);
}

static void test_random_dense_stack_incremental(void)
{
    unsigned long long base = 4242;
    printf("     dense stack seed=%llu\n", base);
    run_scene(base, t_quick ? 40 : 80, t_quick ? 20 : 60, 0);
}

/* the same with hsr_change_many among the steps, and longer sequences: the repairs
 * of several changes at once and the joins after them, checked against a rebuild */
static void test_random_scenes_change_many_equals_rebuild(void)
{
    run_seeds("change_many scenes", 19951126, t_quick ? 4 : 16, 30, 3, 60, 1);
}

void suite_props(void)
{
    RUN(test_random_scenes_disjoint_union_and_rebuild);
    RUN(test_random_dense_stack_incremental);
    RUN(test_random_scenes_change_many_equals_rebuild);
}
