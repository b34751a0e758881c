/* test_fuzz.c - short seeded fuzz run (make test) / longer (make fuzz):
 * mutated OBJ and scene text must give a status, never a crash;
 * degenerate random polygons (repeated points, collinear runs, extreme
 * coordinates) must give consistent domains. */
#include <stdlib.h>
#include <string.h>
#include "t.h"

static const char *SEEDS[] = {
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf -1 -2 -3\nusemtl x\nf 1/1 2//2 3/3/3\n",
    "screen 64 48\ncamera eye 0 0 5 at 0 0 0 up 0 1 0 fov 60\nmaterial m 1 0 0 opacity 0.5\nlight 1 1 1 0.5\n",
};

static int fuzz_text(unsigned long long *s)
{
    char buf[512];
    int which = (int)(t_rand(s) % 2);
    size_t n = strlen(SEEDS[which]);
    memcpy(buf, SEEDS[which], n + 1);
    int muts = 1 + (int)(t_rand(s) % 6);
    const char alphabet[] = "0123456789-+.eE/ \n#fvnaiINF";
    for (int i = 0; i < muts; i++) {
        size_t at = t_rand(s) % n;
        buf[at] = (t_rand(s) % 2) ? alphabet[t_rand(s) % (sizeof alphabet - 1)] : (char)(1 + t_rand(s) % 255);
    }
    if (t_rand(s) % 4 == 0) buf[t_rand(s) % n] = 0;
    hsr_scene *sc;
    char err[256];
    if (hsr_scene_new(&sc) != HSR_OK) return 1;
    hsr_status st = which ? hsr_scene_parse(sc, buf, "f.scene", "/nonexistent", err, sizeof err)
                          : hsr_obj_parse(sc, buf, "f.obj", 0, err, sizeof err);
    int bad = 0;
    if (st == HSR_OK && which == 0) {
        hsr_ctx *h = NULL;
        double *sh = NULL;
        if (hsr_scene_build(sc, &h, &sh) == HSR_OK) bad = hsr_check(h) != HSR_OK;
        free(sh); hsr_destroy(h);
    } else if (st != HSR_OK && strncmp(err, which ? "f.scene:" : "f.obj:", which ? 8 : 6) != 0) bad = 1;
    hsr_scene_free(sc);
    return bad;
}

static int fuzz_poly(unsigned long long *s)
{
    int64_t xy[32];
    int n = (int)(t_rand(s) % 16);
    int64_t scale = (t_rand(s) % 3 == 0) ? HSR_COORD_MAX : 16;
    for (int i = 0; i < 2 * n; i++) {
        int64_t v = (int64_t)(t_rand(s) % (unsigned)(2 * (scale > 1000000 ? 1000 : scale) + 1));
        v -= (scale > 1000000 ? 1000 : scale);
        if (scale > 1000000) v = v * (HSR_COORD_MAX / 1000);
        xy[i] = v;
        if (i >= 2 && t_rand(s) % 5 == 0) xy[i] = xy[i - 2];
    }
    hsr_domain *a = NULL, *b = NULL, *x = NULL;
    int bad = 0;
    if (hsr_domain_from_rings(xy, &n, 1, &a) != HSR_OK) return 1;
    int m = 3;
    int64_t tri[6] = {xy[0 % (2 * n + 1)], 0, 5, 5, -3, 7};
    if (hsr_domain_from_rings(tri, &m, 1, &b) != HSR_OK) bad = 1;
    double aa = hsr_domain_area(a);
    if (aa < 0) bad = 1;
    if (hsr_domain_boolean(a, a, HSR_XOR, &x) != HSR_OK || !hsr_domain_is_empty(x)) bad = 1;
    hsr_domain_free(x); x = NULL;
    if (b && hsr_domain_boolean(a, b, HSR_UNION, &x) == HSR_OK) {
        double u = hsr_domain_area(x), i = t_bool_area(a, b, HSR_INTERSECT);
        if (fabs(u + i - aa - hsr_domain_area(b)) > 1e-9 * (1 + aa + u)) bad = 1;
    } else bad = 1;
    double *r; int *rl, nr;
    if (hsr_domain_rings(a, &r, &rl, &nr) != HSR_OK) bad = 1; else { free(r); free(rl); }
    hsr_domain_free(a); hsr_domain_free(b); hsr_domain_free(x);
    return bad;
}

int fuzz_run(int iterations, unsigned long long seed)
{
    printf("fuzz: %d iterations, seed=%llu\n", iterations, seed);
    unsigned long long s = seed;
    int bad = 0;
    for (int i = 0; i < iterations; i++) {
        int b = (i % 2) ? fuzz_text(&s) : fuzz_poly(&s);
        if (b) { bad++; fprintf(stderr, "fuzz failure at iteration %d (seed=%llu)\n", i, seed); }
    }
    return bad;
}
