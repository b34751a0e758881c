/* test_main.c - runs every suite of sw/hsr; prints "N passed, M failed" last. */
#include <stdlib.h>
#include <string.h>
#include "t.h"

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
    return t_report();
}
