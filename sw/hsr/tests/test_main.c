/* test_main.c - runs every suite; prints "N passed, M failed" last. */
#include <stdlib.h>
#include <string.h>
#include "t.h"

int t_failed_now, t_quick;
const char *t_name;
static int n_pass, n_fail;

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

int main(int argc, char **argv)
{
    int fuzz = -1;
    unsigned long long seed = 12345;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--quick")) t_quick = 1;
        else if (!strcmp(argv[i], "--fuzz") && i + 1 < argc) fuzz = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--seed") && i + 1 < argc) seed = strtoull(argv[++i], NULL, 10);
    }
    if (getenv("SEED")) seed = strtoull(getenv("SEED"), NULL, 10);
    if (fuzz >= 0) {
        int bad = fuzz_run(fuzz, seed);
        printf("%d passed, %d failed\n", fuzz - bad, bad);
        return bad != 0;
    }
    suite_domain();
    suite_separate();
    suite_grid();
    suite_hsr();
    suite_props();
    suite_io();
    suite_obj();
    suite_yp();
    printf("%d passed, %d failed\n", n_pass, n_fail);
    return n_fail != 0;
}
