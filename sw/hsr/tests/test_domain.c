/* test_domain.c - polygon -> Sorted-Edge conversion and domain queries. */
#include <stdlib.h>
#include "t.h"

static double ring_area(const double *xy, int n)
{
    double a = 0;
    for (int i = 0; i < n; i++) {
        int j = (i + 1) % n;
        a += xy[2 * i] * xy[2 * j + 1] - xy[2 * j] * xy[2 * i + 1];
    }
    return a / 2;
}

static double rings_area(const hsr_domain *d, int *nrings)
{
    double *xy; int *len, nr;
    if (hsr_domain_rings(d, &xy, &len, &nr) != HSR_OK) return -1;
    double a = 0; int off = 0;
    for (int r = 0; r < nr; r++) { a += ring_area(xy + 2 * off, len[r]); off += len[r]; }
    if (nrings) *nrings = nr;
    free(xy); free(len);
    return a;
}

/* stabbing queries in storage order must report x monotonically */
static int sorted_edge_order_ok(const hsr_domain *d)
{
    int n = hsr_domain_edge_count(d);
    hsr_extent e = hsr_domain_extent(d);
    for (int k = 0; k <= 64; k++) {
        double y = e.bot + (e.top - e.bot) * (k + 0.5) / 65.0, last = -1e300;
        for (int i = 0; i < n; i++) {
            double s[4];
            hsr_domain_edge(d, i, s);
            if (!(s[1] <= y && y < s[3])) continue;
            double x = s[0] + (s[2] - s[0]) * (y - s[1]) / (s[3] - s[1]);
            if (x < last - 1e-6) return 0;
            last = x;
        }
    }
    return 1;
}

static void test_square_area_and_two_edges(void)
{
    hsr_domain *d = t_rect(0, 0, 10, 20);
    CHECK(d && hsr_domain_edge_count(d) == 2);
    CHECK_NEAR(hsr_domain_area(d), 200, 1e-12);
    hsr_extent e = hsr_domain_extent(d);
    CHECK(e.left == 0 && e.bot == 0 && e.right == 10 && e.top == 20);
    hsr_domain_free(d);
}

static void test_collinear_vertices_joined(void)
{
    int64_t xy[] = {0, 0, 5, 0, 10, 0, 10, 5, 10, 10, 10, 20, 5, 20, 0, 20, 0, 7};
    hsr_domain *d = t_poly(xy, 9);
    CHECK(d && hsr_domain_edge_count(d) == 2);
    CHECK_NEAR(hsr_domain_area(d), 200, 1e-12);
    hsr_domain_free(d);
}

static void test_zero_area_polygon_is_empty(void)
{
    int64_t line[] = {0, 0, 5, 5, 10, 10};
    hsr_domain *d = t_poly(line, 3);
    CHECK(d && hsr_domain_is_empty(d) && hsr_domain_area(d) == 0);
    hsr_domain_free(d);
    int64_t back[] = {0, 0, 10, 0, 10, 10, 10, 0};     /* spike: double edge */
    d = t_poly(back, 4);
    CHECK(d && hsr_domain_is_empty(d));
    hsr_domain_free(d);
    int64_t two[] = {3, 3, 7, 9};
    d = t_poly(two, 2);
    CHECK(d && hsr_domain_is_empty(d));
    hsr_domain_free(d);
}

static void test_double_edges_cancel(void)
{
    /* two squares in one ring joined by a doubled bridge edge */
    int64_t xy[] = {0, 0, 10, 0, 10, 10, 20, 10, 20, 20, 10, 20, 10, 10, 0, 10};
    hsr_domain *d = t_poly(xy, 8);
    CHECK_NEAR(hsr_domain_area(d), 200, 1e-12);
    CHECK(sorted_edge_order_ok(d));
    hsr_domain_free(d);
}

static void test_self_intersecting_bowtie_subdivided(void)
{
    int64_t xy[] = {0, 0, 10, 10, 10, 0, 0, 10};
    hsr_domain *d = t_poly(xy, 4);
    CHECK(d && hsr_domain_edge_count(d) == 6);   /* 2 verticals + 4 halves */
    CHECK_NEAR(hsr_domain_area(d), 50, 1e-12);
    CHECK(sorted_edge_order_ok(d));
    hsr_domain_free(d);
}

static void test_hole_even_odd(void)
{
    int64_t xy[] = {0, 0, 30, 0, 30, 30, 0, 30, 10, 10, 20, 10, 20, 20, 10, 20};
    int len[2] = {4, 4};
    hsr_domain *d = NULL;
    CHECK(hsr_domain_from_rings(xy, len, 2, &d) == HSR_OK);
    CHECK_NEAR(hsr_domain_area(d), 800, 1e-12);
    CHECK(!hsr_domain_contains(d, 15, 15));
    CHECK(hsr_domain_contains(d, 5, 15));
    int nr = 0;
    CHECK_NEAR(rings_area(d, &nr), 800, 1e-9);
    CHECK(nr == 2);
    hsr_domain_free(d);
}

static void test_disconnected_and_concave(void)
{
    int64_t u[] = {0, 0, 30, 0, 30, 30, 20, 30, 20, 10, 10, 10, 10, 30, 0, 30};
    hsr_domain *d = t_poly(u, 8);
    CHECK_NEAR(hsr_domain_area(d), 700, 1e-12);
    CHECK(!hsr_domain_contains(d, 15, 20) && hsr_domain_contains(d, 5, 20));
    CHECK(sorted_edge_order_ok(d));
    CHECK_NEAR(rings_area(d, NULL), 700, 1e-9);
    hsr_domain_free(d);
    int64_t xy[] = {0, 0, 1, 0, 1, 1, 0, 1, 5, 5, 6, 5, 6, 6, 5, 6};
    int len[2] = {4, 4};
    CHECK(hsr_domain_from_rings(xy, len, 2, &d) == HSR_OK);
    CHECK_NEAR(hsr_domain_area(d), 2, 1e-12);
    int nr = 0;
    CHECK_NEAR(rings_area(d, &nr), 2, 1e-9);
    CHECK(nr == 2);
    hsr_domain_free(d);
}

static void test_shared_edge_union_joins(void)
{
    hsr_domain *a = t_rect(0, 0, 10, 10), *b = t_rect(10, 0, 20, 10), *u = NULL;
    CHECK(hsr_domain_boolean(a, b, HSR_UNION, &u) == HSR_OK);
    CHECK(hsr_domain_edge_count(u) == 2);
    CHECK_NEAR(hsr_domain_area(u), 200, 1e-12);
    CHECK(t_bool_area(a, b, HSR_INTERSECT) == 0);
    hsr_domain_free(a); hsr_domain_free(b); hsr_domain_free(u);
}

static void test_t_junction_vertex_on_edge(void)
{
    /* triangle whose apex lies exactly on the square's right edge */
    hsr_domain *a = t_rect(0, 0, 10, 10);
    int64_t tri[] = {10, 5, 20, 0, 20, 10};
    hsr_domain *b = t_poly(tri, 3), *u = NULL;
    CHECK(t_bool_area(a, b, HSR_INTERSECT) == 0);
    CHECK(hsr_domain_boolean(a, b, HSR_UNION, &u) == HSR_OK);
    CHECK_NEAR(hsr_domain_area(u), 150, 1e-12);
    CHECK_NEAR(rings_area(u, NULL), 150, 1e-9);
    CHECK(sorted_edge_order_ok(u));
    hsr_domain_free(a); hsr_domain_free(b); hsr_domain_free(u);
}

static void test_point_in_domain_half_open(void)
{
    hsr_domain *a = t_rect(0, 0, 10, 10), *b = t_rect(10, 0, 20, 10);
    for (int64_t y = -1; y <= 11; y++)
        for (int64_t x = -1; x <= 21; x++) {
            int ia = hsr_domain_contains(a, x, y), ib = hsr_domain_contains(b, x, y);
            int inside = x >= 0 && x < 20 && y >= 0 && y < 10;
            CHECK(ia + ib == inside);
        }
    hsr_domain_free(a); hsr_domain_free(b);
}

static void test_bad_input_returns_status(void)
{
    hsr_domain *d = (hsr_domain *)1;
    int64_t big[] = {0, 0, HSR_COORD_MAX + 1, 0, 0, 5};
    int n = 3, neg = -1;
    CHECK(hsr_domain_from_rings(big, &n, 1, &d) == HSR_ERANGE && d == NULL);
    CHECK(hsr_domain_from_rings(NULL, &n, 1, &d) == HSR_EINVAL);
    CHECK(hsr_domain_from_rings(big, &neg, 1, &d) == HSR_EINVAL);
    CHECK(hsr_domain_from_rings(big, &n, -2, &d) == HSR_EINVAL);
    CHECK(hsr_domain_from_rings(big, &n, 1, NULL) == HSR_EINVAL);
    CHECK(hsr_domain_from_rings(NULL, NULL, 0, &d) == HSR_OK && hsr_domain_is_empty(d));
    hsr_domain_free(d);
    CHECK(hsr_domain_area(NULL) == 0 && hsr_domain_boolean(NULL, NULL, HSR_UNION, &d) == HSR_EINVAL);
}

static void test_extreme_coordinates_exact(void)
{
    int64_t M = HSR_COORD_MAX;
    int64_t xy[] = {-M, -M, M, -M + 1, M - 1, M, -M + 3, M - 2};
    hsr_domain *a = t_poly(xy, 4);
    int64_t xy2[] = {-M, M, -M + 1, -M, M, -M + 2, M, M - 1};
    hsr_domain *b = t_poly(xy2, 4);
    double aa = hsr_domain_area(a), ab = hsr_domain_area(b);
    double u = t_bool_area(a, b, HSR_UNION), i = t_bool_area(a, b, HSR_INTERSECT);
    CHECK(aa > 0 && ab > 0);
    CHECK_NEAR(u + i, aa + ab, 1e-12);
    CHECK(fabs(t_bool_area(a, b, HSR_XOR) - (u - i)) <= 1e-12 * (aa + ab));
    hsr_domain_free(a); hsr_domain_free(b);
}

static void test_random_polygons_rings_and_order(void)
{
    unsigned long long seed = 777;
    printf("     random polygons seed=%llu\n", seed);
    for (int it = 0; it < (t_quick ? 40 : 200); it++) {
        int n = 3 + (int)(t_rand(&seed) % 9);
        int64_t xy[24];
        for (int i = 0; i < 2 * n; i++) xy[i] = (int64_t)(t_rand(&seed) % 64);
        hsr_domain *d = t_poly(xy, n);
        CHECK(d != NULL);
        if (!d) continue;
        CHECK(sorted_edge_order_ok(d));
        CHECK_NEAR(rings_area(d, NULL), hsr_domain_area(d), 1e-9);
        /* domain of its own rings is the same set */
        double *rx; int *rl, nr;
        if (hsr_domain_rings(d, &rx, &rl, &nr) == HSR_OK) {
            int total = 0;
            for (int r = 0; r < nr; r++) total += rl[r];
            int64_t *ix = malloc(sizeof(int64_t) * 2 * (size_t)(total + 1));
            int exact = 1;
            for (int k = 0; k < 2 * total; k++) { ix[k] = llround(rx[k]); if (fabs(rx[k] - ix[k]) > 1e-9) exact = 0; }
            if (exact) {
                hsr_domain *e = NULL;
                CHECK(hsr_domain_from_rings(ix, rl, nr, &e) == HSR_OK);
                CHECK(t_bool_area(d, e, HSR_XOR) <= 1e-9);
                hsr_domain_free(e);
            }
            free(ix); free(rx); free(rl);
        } else CHECK(0);
        hsr_domain_free(d);
    }
}

void suite_domain(void)
{
    RUN(test_square_area_and_two_edges);
    RUN(test_collinear_vertices_joined);
    RUN(test_zero_area_polygon_is_empty);
    RUN(test_double_edges_cancel);
    RUN(test_self_intersecting_bowtie_subdivided);
    RUN(test_hole_even_odd);
    RUN(test_disconnected_and_concave);
    RUN(test_shared_edge_union_joins);
    RUN(test_t_junction_vertex_on_edge);
    RUN(test_point_in_domain_half_open);
    RUN(test_bad_input_returns_status);
    RUN(test_extreme_coordinates_exact);
    RUN(test_random_polygons_rings_and_order);
}
