/* test_grid.c - Grid-List / Slice-List queries equal brute force. */
#include <stdlib.h>
#include "t.h"

static void mark(int id, void *ctx) { ((char *)ctx)[id]++; }

static void grid_vs_bruteforce(int nx, int ny)
{
    enum { N = 400 };
    unsigned long long seed = 99 + (unsigned long long)nx * 7 + (unsigned long long)ny;
    hsr_extent win = {0, 0, 10000, 10000}, ex[N];
    hsr_gridlist *g = NULL;
    CHECK(hsr_gridlist_create(win, nx, ny, &g) == HSR_OK);
    if (!g) return;
    for (int i = 0; i < N; i++) {
        int64_t x = (int64_t)(t_rand(&seed) % 11000) - 500, y = (int64_t)(t_rand(&seed) % 11000) - 500;
        int64_t w = (int64_t)(t_rand(&seed) % (i % 10 == 0 ? 5000 : 300)), h = (int64_t)(t_rand(&seed) % 300);
        ex[i] = (hsr_extent){x, y, x + w, y + h};
        CHECK(hsr_gridlist_insert(g, i, ex[i]) == HSR_OK);
    }
    for (int i = 0; i < N; i += 3) CHECK(hsr_gridlist_remove(g, i) == HSR_OK);
    CHECK(hsr_gridlist_remove(g, 0) == HSR_ENOTFOUND);
    for (int q = 0; q < 200; q++) {
        int64_t x = (int64_t)(t_rand(&seed) % 10000), y = (int64_t)(t_rand(&seed) % 10000);
        hsr_extent Q = {x, y, x + (int64_t)(t_rand(&seed) % 500), y + (int64_t)(t_rand(&seed) % 500)};
        char hit[N] = {0};
        CHECK(hsr_gridlist_query(g, Q, mark, hit) >= 0);
        for (int i = 0; i < N; i++) CHECK(hit[i] == (i % 3 != 0 && hsr_extent_overlap(ex[i], Q)));
    }
    hsr_gridlist_free(g);
}

static void test_gridlist_query_matches_bruteforce(void)
{
    grid_vs_bruteforce(1, 1);
    grid_vs_bruteforce(7, 5);
    grid_vs_bruteforce(64, 64);
}

static void test_slicelist_is_one_column_grid(void) { grid_vs_bruteforce(1, 100); }

static void test_gridlist_bad_args(void)
{
    hsr_gridlist *g = NULL;
    hsr_extent w = {0, 0, 10, 10}, bad = {5, 5, 4, 4};
    CHECK(hsr_gridlist_create(w, 0, 1, &g) == HSR_EINVAL);
    CHECK(hsr_gridlist_create(bad, 1, 1, &g) == HSR_EINVAL);
    CHECK(hsr_gridlist_create(w, 2, 2, &g) == HSR_OK);
    CHECK(hsr_gridlist_insert(g, -1, w) == HSR_EINVAL);
    CHECK(hsr_gridlist_insert(g, 3, bad) == HSR_EINVAL);
    CHECK(hsr_gridlist_insert(g, 3, w) == HSR_OK);
    CHECK(hsr_gridlist_insert(g, 3, w) == HSR_EINVAL);
    CHECK(hsr_gridlist_query(g, w, NULL, NULL) == -1);
    hsr_gridlist_free(g);
}

void suite_grid(void)
{
    RUN(test_gridlist_query_matches_bruteforce);
    RUN(test_slicelist_is_one_column_grid);
    RUN(test_gridlist_bad_args);
}
