/* test_hsr.c - incremental HSR: add, remove (damage repair), move,
 * transparency, pick. */
#include <stdlib.h>
#include "t.h"

hsr_ctx *t_ctx(void)
{
    hsr_config cfg = {{0, 0, 4096, 4096}, 8, 8};
    hsr_ctx *h = NULL;
    hsr_create(&cfg, &h);
    return h;
}

int t_add_rect(hsr_ctx *h, int64_t l, int64_t b, int64_t r, int64_t t, double za, double zc, double op)
{
    int64_t xy[8] = {l, b, r, b, r, t, l, t};
    int n = 4, id = -1;
    hsr_plane p = {za, 0, zc};
    if (hsr_add(h, xy, &n, 1, p, op, &id) != HSR_OK) return -1;
    return id;
}

static int llr_count(const hsr_ctx *h)
{
    int c = 0;
    for (int s = 0; s < hsr_llr_slots(h); s++) c += hsr_llr_get(h, s, NULL, NULL, NULL, NULL);
    return c;
}

static void test_hsr_two_opaque_overlap_any_order(void)
{
    for (int order = 0; order < 2; order++) {
        hsr_ctx *h = t_ctx();
        int a, b;
        if (order == 0) { a = t_add_rect(h, 0, 0, 20, 20, 0, 1, 1); b = t_add_rect(h, 10, 10, 30, 30, 0, 0, 1); }
        else { b = t_add_rect(h, 10, 10, 30, 30, 0, 0, 1); a = t_add_rect(h, 0, 0, 20, 20, 0, 1, 1); }
        CHECK(a >= 0 && b >= 0);
        CHECK_NEAR(t_visible_area(h, a), 300, 1e-12);
        CHECK_NEAR(t_visible_area(h, b), 400, 1e-12);
        CHECK(llr_count(h) == 2);
        CHECK(hsr_check(h) == HSR_OK);
        hsr_destroy(h);
    }
}

static void test_hsr_tri_steps_all_visible_tri_spets_one_visible(void)
{
    hsr_ctx *h = t_ctx(), *g = t_ctx();
    for (int i = 0; i < 30; i++) {
        int64_t s = 1000 - 30 * i;
        int64_t tri[6] = {0, 0, s, 0, 0, s};
        int n = 3, id;
        hsr_plane near = {0, 0, (double)-i}, far = {0, 0, (double)i};
        CHECK(hsr_add(h, tri, &n, 1, near, 1, &id) == HSR_OK);   /* smaller ones in front */
        CHECK(hsr_add(g, tri, &n, 1, far, 1, &id) == HSR_OK);    /* smaller ones behind */
    }
    CHECK(llr_count(h) == 30 && llr_count(g) == 1);
    CHECK_NEAR(t_llr_total_area(h), 500000, 1e-12);
    CHECK_NEAR(t_llr_total_area(g), 500000, 1e-12);
    CHECK(hsr_check(h) == HSR_OK && hsr_check(g) == HSR_OK);
    hsr_destroy(h); hsr_destroy(g);
}

/* An opaque domain in front that covers whole LLR domains takes over one slot
 * and its parent list (add_domain's covered-slot shortcut): tri-spets reversed,
 * a transparent prefix moved to the hidden parents, two covered domains with
 * parent lists of different length, then removals that must repair from the
 * hidden parents. */
static void test_hsr_cover_takes_over_slot_tri_spets_reversed(void)
{
    hsr_ctx *h = t_ctx();
    int ids[30];
    for (int k = 0; k < 30; k++) {   /* smallest (farthest) first, each new one covers all */
        int i = 29 - k;
        int64_t s = 1000 - 30 * i;
        int64_t tri[6] = {0, 0, s, 0, 0, s};
        int n = 3;
        hsr_plane p = {0, 0, (double)i};
        CHECK(hsr_add(h, tri, &n, 1, p, k == 10 ? 0.5 : 1, &ids[k]) == HSR_OK);
    }
    const int *par; int nv, np, front = -1;
    CHECK(llr_count(h) == 1 && hsr_check(h) == HSR_OK);
    for (int s = 0; s < hsr_llr_slots(h); s++)
        if (hsr_llr_get(h, s, NULL, &par, &nv, &np)) { front = par[0]; CHECK(nv == 1 && np == 30); }
    CHECK(front == ids[29]);
    CHECK_NEAR(t_visible_area(h, ids[29]), 500000, 1e-12);
    CHECK(hsr_remove(h, ids[29]) == HSR_OK && hsr_check(h) == HSR_OK);
    CHECK_NEAR(t_llr_total_area(h), 970.0 * 970.0 / 2, 1e-9);
    CHECK_NEAR(t_visible_area(h, ids[28]), 970.0 * 970.0 / 2, 1e-9);

    /* transparent prefix: a glass square over an opaque one, then an opaque cover */
    hsr_ctx *g = t_ctx();
    int a = t_add_rect(g, 0, 0, 100, 100, 0, 5, 1);
    int gl = t_add_rect(g, 0, 0, 100, 100, 0, 4, 0.5);
    int b = t_add_rect(g, 200, 0, 260, 100, 0, 5, 1);        /* a second, shorter-listed domain */
    int c = t_add_rect(g, -10, -10, 300, 120, 0, 1, 1);      /* covers both */
    CHECK(a >= 0 && gl >= 0 && b >= 0 && c >= 0);
    CHECK(llr_count(g) == 1 && hsr_check(g) == HSR_OK);
    int nvis, ninv;
    CHECK(hsr_mlr_get(g, gl, NULL, NULL, NULL, &nvis, &ninv) && nvis == 0 && ninv == 1);
    CHECK_NEAR(t_visible_area(g, c), 310.0 * 130, 1e-9);
    CHECK(hsr_remove(g, c) == HSR_OK && hsr_check(g) == HSR_OK);
    CHECK_NEAR(t_visible_area(g, gl), 10000, 1e-9);
    CHECK_NEAR(t_visible_area(g, b), 6000, 1e-9);
    CHECK(hsr_mlr_get(g, a, NULL, NULL, NULL, &nvis, &ninv) && nvis == 1 && ninv == 0);
    hsr_destroy(h); hsr_destroy(g);
}

static void test_hsr_remove_repairs_damage(void)
{
    hsr_ctx *h = t_ctx();
    int a = t_add_rect(h, 0, 0, 20, 20, 0, 2, 1);
    int b = t_add_rect(h, 5, 5, 15, 15, 0, 1, 1);
    int c = t_add_rect(h, 8, 8, 12, 12, 0, 0, 1);
    int nv, ni;
    CHECK(hsr_mlr_get(h, b, NULL, NULL, NULL, &nv, &ni) && nv == 1 && ni >= 1);
    CHECK(hsr_remove(h, b) == HSR_OK);
    CHECK(hsr_check(h) == HSR_OK);
    CHECK_NEAR(t_visible_area(h, a), 400 - 16, 1e-12);
    CHECK_NEAR(t_visible_area(h, c), 16, 1e-12);
    CHECK(hsr_remove(h, b) == HSR_ENOTFOUND);
    CHECK(hsr_remove(h, c) == HSR_OK);
    CHECK_NEAR(t_visible_area(h, a), 400, 1e-12);
    CHECK(llr_count(h) == 1);
    CHECK(hsr_check(h) == HSR_OK);
    hsr_destroy(h);
}

static void test_hsr_transparent_parents_and_pick(void)
{
    hsr_ctx *h = t_ctx();
    int o = t_add_rect(h, 0, 0, 20, 20, 0, 1, 1);
    int t = t_add_rect(h, 10, 10, 30, 30, 0, 0, 0.5);
    int id = -1;
    CHECK(hsr_pick(h, 15, 15, HSR_PICK_VISIBLE, &id) == HSR_OK && id == t);
    CHECK(hsr_pick(h, 15, 15, HSR_PICK_NEXT_BEHIND, &id) == HSR_OK && id == o);
    CHECK(hsr_pick(h, 15, 15, HSR_PICK_FIRST_OPAQUE, &id) == HSR_OK && id == o);
    CHECK(hsr_pick(h, 25, 25, HSR_PICK_FIRST_OPAQUE, &id) == HSR_ENOTFOUND);
    CHECK(hsr_pick(h, 5, 5, HSR_PICK_VISIBLE, &id) == HSR_OK && id == o);
    CHECK(hsr_pick(h, 100, 100, HSR_PICK_VISIBLE, &id) == HSR_ENOTFOUND);
    int nv;
    CHECK(hsr_mlr_get(h, t, NULL, NULL, NULL, &nv, NULL) && nv == 2);
    CHECK_NEAR(t_visible_area(h, t), 400, 1e-12);
    CHECK(hsr_set_opacity(h, t, 1.0) == HSR_OK);
    CHECK(hsr_pick(h, 15, 15, HSR_PICK_NEXT_BEHIND, &id) == HSR_OK && id == o);
    CHECK(hsr_mlr_get(h, t, NULL, NULL, NULL, &nv, NULL) && nv == 1);
    CHECK(llr_count(h) == 2 && hsr_check(h) == HSR_OK);
    CHECK(hsr_set_opacity(h, o, 0.25) == HSR_OK && hsr_check(h) == HSR_OK);
    CHECK(hsr_pick(h, 5, 5, HSR_PICK_FIRST_OPAQUE, &id) == HSR_ENOTFOUND);
    hsr_destroy(h);
}

static void test_hsr_interpenetrating_squares(void)
{
    hsr_ctx *h = t_ctx();
    int a = t_add_rect(h, 0, 0, 20, 20, 1, -15, 1);
    int b = t_add_rect(h, 10, 10, 30, 30, 0, 0, 1);
    CHECK_NEAR(t_visible_area(h, a), 350, 1e-12);
    CHECK_NEAR(t_visible_area(h, b), 350, 1e-12);
    int id;
    CHECK(hsr_pick(h, 14, 15, HSR_PICK_VISIBLE, &id) == HSR_OK && id == a);
    CHECK(hsr_pick(h, 16, 15, HSR_PICK_VISIBLE, &id) == HSR_OK && id == b);
    CHECK(hsr_check(h) == HSR_OK);
    hsr_destroy(h);
}

static void test_hsr_coincident_planes_lower_id_in_front(void)
{
    hsr_ctx *h = t_ctx();
    int a = t_add_rect(h, 10, 10, 30, 30, 0.5, 2, 1);
    int b = t_add_rect(h, 0, 0, 20, 20, 0.5, 2, 1);
    CHECK_NEAR(t_visible_area(h, a), 400, 1e-12);
    CHECK_NEAR(t_visible_area(h, b), 300, 1e-12);
    hsr_destroy(h);
}

static void test_hsr_move_then_rebuild_identical(void)
{
    hsr_ctx *h = t_ctx();
    int a = t_add_rect(h, 0, 0, 20, 20, 0, 1, 1);
    t_add_rect(h, 10, 10, 30, 30, 0, 0, 1);
    int64_t xy[8] = {25, 25, 45, 25, 45, 45, 25, 45};
    int n = 4;
    hsr_plane p = {0, 0, -1};
    CHECK(hsr_move(h, a, xy, &n, 1, p) == HSR_OK);
    CHECK(hsr_check(h) == HSR_OK);
    double va = t_visible_area(h, a), vb = t_visible_area(h, 1);
    CHECK_NEAR(va, 400, 1e-12); CHECK_NEAR(vb, 400 - 25, 1e-12);
    CHECK(hsr_rebuild(h) == HSR_OK && hsr_check(h) == HSR_OK);
    CHECK_NEAR(t_visible_area(h, a), va, 1e-12); CHECK_NEAR(t_visible_area(h, 1), vb, 1e-12);
    hsr_destroy(h);
}

static void test_hsr_bad_arguments(void)
{
    hsr_ctx *h = t_ctx();
    int64_t xy[6] = {0, 0, 10, 0, 0, 10};
    int n = 3, id;
    hsr_plane ok = {0, 0, 0}, nan = {NAN, 0, 0}, inf = {0, INFINITY, 0};
    CHECK(hsr_add(h, xy, &n, 1, nan, 1, &id) == HSR_EINVAL);
    CHECK(hsr_add(h, xy, &n, 1, inf, 1, &id) == HSR_EINVAL);
    CHECK(hsr_add(h, xy, &n, 1, ok, 2.0, &id) == HSR_EINVAL);
    CHECK(hsr_add(h, xy, &n, 1, ok, NAN, &id) == HSR_EINVAL);
    CHECK(hsr_add(NULL, xy, &n, 1, ok, 1, &id) == HSR_EINVAL);
    CHECK(hsr_remove(h, 7) == HSR_ENOTFOUND && hsr_remove(h, -1) == HSR_ENOTFOUND);
    CHECK(hsr_set_opacity(h, 0, 0.5) == HSR_ENOTFOUND);
    CHECK(hsr_pick(h, 0, 0, HSR_PICK_VISIBLE, NULL) == HSR_EINVAL);
    int64_t flat[6] = {0, 0, 5, 5, 10, 10};
    CHECK(hsr_add(h, flat, &n, 1, ok, 1, &id) == HSR_OK && t_llr_total_area(h) == 0);
    CHECK(hsr_remove(h, id) == HSR_OK && hsr_check(h) == HSR_OK);
    hsr_config bad = {{0, 0, 0, 0}, 8, 8};
    hsr_ctx *g = NULL;
    CHECK(hsr_create(&bad, &g) == HSR_EINVAL && g == NULL);
    hsr_destroy(h);
}

void suite_hsr(void)
{
    RUN(test_hsr_two_opaque_overlap_any_order);
    RUN(test_hsr_tri_steps_all_visible_tri_spets_one_visible);
    RUN(test_hsr_cover_takes_over_slot_tri_spets_reversed);
    RUN(test_hsr_remove_repairs_damage);
    RUN(test_hsr_transparent_parents_and_pick);
    RUN(test_hsr_interpenetrating_squares);
    RUN(test_hsr_coincident_planes_lower_id_in_front);
    RUN(test_hsr_move_then_rebuild_identical);
    RUN(test_hsr_bad_arguments);
}
