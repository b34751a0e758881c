/* t.c - the test harness of the C libraries (sw/hsr, sw/yproc): RUN, the
 * pass/fail count, and helpers that build domains and load test scenes. */
#include <stdlib.h>
#include <string.h>
#include "t.h"

int t_failed_now, t_quick;
const char *t_name;
static int n_pass, n_fail;

int t_report(void)
{
    printf("%d passed, %d failed\n", n_pass, n_fail);
    return n_fail != 0;
}

void t_run(const char *name, void (*fn)(void))
{
    t_name = name; t_failed_now = 0;
    fn();
    if (t_failed_now) { n_fail++; printf("FAIL %s\n", name); }
    else { n_pass++; printf("ok   %s\n", name); }
    fflush(stdout);
}

hsr_domain *t_poly(const int64_t *xy, int n)
{
    hsr_domain *d = NULL;
    if (hsr_domain_from_rings(xy, &n, 1, &d) != HSR_OK) return NULL;
    return d;
}

hsr_domain *t_rect(int64_t l, int64_t b, int64_t r, int64_t t)
{
    int64_t xy[8] = {l, b, r, b, r, t, l, t};
    return t_poly(xy, 4);
}

double t_bool_area(const hsr_domain *a, const hsr_domain *b, hsr_boolop op)
{
    hsr_domain *o = NULL;
    if (hsr_domain_boolean(a, b, op, &o) != HSR_OK) return -1;
    double ar = hsr_domain_area(o);
    hsr_domain_free(o);
    return ar;
}

unsigned t_rand(unsigned long long *s)
{
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (unsigned)(*s >> 33);
}

hsr_scene *t_load_obj(const char *dir, const char *obj, char *err, size_t n)
{
    char text[1024], name[512];
    snprintf(text, sizeof text, T_OBJ_SCENE_HEAD "obj %s material grey\n", obj);
    snprintf(name, sizeof name, "%s/t.scene", dir);
    hsr_scene *sc = NULL;
    if (hsr_scene_new(&sc) != HSR_OK) return NULL;
    snprintf(sc->name, sizeof sc->name, "%s", name);
    if (hsr_scene_parse(sc, text, name, dir, err, n) != HSR_OK) {
        fprintf(stderr, "  %s\n", err);
        hsr_scene_free(sc);
        return NULL;
    }
    return sc;
}

double t_visible_area(const hsr_ctx *h, int id)
{
    double a = 0;
    for (int s = 0; s < hsr_llr_slots(h); s++) {
        const hsr_domain *d; const int *par; int nv, np;
        if (hsr_llr_get(h, s, &d, &par, &nv, &np) && par[0] == id) a += hsr_domain_area(d);
    }
    return a;
}

double t_llr_total_area(const hsr_ctx *h)
{
    double a = 0;
    for (int s = 0; s < hsr_llr_slots(h); s++) {
        const hsr_domain *d;
        if (hsr_llr_get(h, s, &d, NULL, NULL, NULL)) a += hsr_domain_area(d);
    }
    return a;
}
