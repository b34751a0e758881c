/* yproc_serve.c - `yproc serve SCENE --dir DIR` (docs/viewer.md): the scene held in one
 * long-lived process for the interactive viewer (sw/diffengine/viewer).  Requests are
 * read from stdin, one line of words each; every request is answered with exactly one
 * JSON line on stdout ("ok": true | false with "error").  A frame's changed lines are
 * written to DIR/{r,g,b}.de48 (only those lines, in order; the reply lists them).
 *
 *   info                          scene, camera, objects, materials, lights
 *   pick X Y                      the visible part at pixel (X, Y): face, obj, material,
 *                                 visible area (px^2) and the obj's screen box
 *   move OBJ DX DY DZ             obj's world offset from its place in the scene file
 *                                 (absolute: undo sets the old offset again)
 *   opacity MATERIAL A            material opacity in [0, 1]
 *   light L DX DY DZ              direction of light L (towards the light)
 *   options AA SHADING            AA 0|1, SHADING flat|gouraud|phong (every line re-scanned)
 *   frame full|coarse             scan the damaged lines; coarse: no AA and flat shading
 *                                 (adaptive degradation, section 7.5), remembered and
 *                                 refined by the next full frame
 *   quit
 *
 * A move is one hsr_change_many of the object's faces (one damage repair).  When an
 * object's last move cost more than the last full build, the HSR is rebuilt from the scene
 * instead (hsr_scene_build: the same visible result; only the object's old and new rows are
 * re-scanned); each rebuild re-measures the build and halves the object's move estimate, so
 * a move slowed once by the machine's load is tried again a few steps later.  (A rule
 * "rebuild when the object has more than a quarter of the faces" no longer pays: dragging
 * the 624-face ball of the 788-face CAD scene, one change_many costs less than a build.)
 * Times are wall-clock ms (CLOCK_MONOTONIC): the viewer's latency is wall time. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "yproc_tools.h"

static double wall_ms(void) { return yproc_clock_ms(CLOCK_MONOTONIC); }

typedef struct server {
    hsr_scene *sc;
    hsr_ctx *h;
    yp_shader *sh;
    yp_frame *fr;
    yp_options yo;
    const char *dir;
    double *base_v, *off;         /* scene-file vertices; per obj world offset */
    int *vobj;                    /* per vertex: obj or -1 */
    int *ofaces, *ofirst;         /* faces of obj o: ofaces[ofirst[o] .. ofirst[o + 1]] */
    yp_cmdlist *prev;             /* [3 * H] the lines last sent */
    char *coarse;                 /* [H] 1: last scanned coarse, to refine */
    int y0, y1;                   /* damaged rows not yet scanned */
    double hsr_ms;                /* HSR time since the last frame */
    int rebuilt;                  /* the last HSR update was a full build */
    double build_ms;              /* the last full HSR build of the scene */
    double *move_ms;              /* per obj: its last move (halved by each rebuild) */
} server;

static void reply_error(const char *fmt, const char *arg)
{
    char msg[512];
    snprintf(msg, sizeof msg, fmt, arg ? arg : "");
    printf("{\"ok\": false, \"error\": \"");
    for (const char *p = msg; *p; p++) {
        if (*p == '"' || *p == '\\') printf("\\%c", *p);
        else if ((unsigned char)*p < 32) printf(" ");
        else putchar(*p);
    }
    printf("\"}\n");
}

static void damage(server *s, int a, int b)
{
    int H = s->sc->height;
    if (a < 0) a = 0;
    if (b > H) b = H;
    if (a >= b) return;
    if (s->y0 >= s->y1) { s->y0 = a; s->y1 = b; return; }
    if (a < s->y0) s->y0 = a;
    if (b > s->y1) s->y1 = b;
}

/* the rows face id covers in the HSR now (nothing if empty) */
static void damage_face(server *s, int id)
{
    const hsr_domain *d;
    if (!hsr_mlr_get(s->h, id, &d, NULL, NULL, NULL, NULL) || hsr_domain_is_empty(d)) return;
    hsr_extent e = hsr_domain_extent(d);
    damage(s, (int)floor((double)e.bot / HSR_SUBPIXEL), (int)ceil((double)e.top / HSR_SUBPIXEL) + 1);
}

/* a fresh HSR of the scene; obj >= 0: damage its faces' old and new rows only */
static hsr_status rebuild(server *s, int obj)
{
    hsr_ctx *h;
    double *shade;
    for (int i = s->ofirst[obj]; i < s->ofirst[obj + 1]; i++) damage_face(s, s->ofaces[i]);
    hsr_status st = hsr_scene_build(s->sc, &h, &shade);
    if (st != HSR_OK) return st;
    free(shade);
    hsr_destroy(s->h);
    s->h = h;
    for (int i = s->ofirst[obj]; i < s->ofirst[obj + 1]; i++) damage_face(s, s->ofaces[i]);
    return HSR_OK;
}

static int server_open(server *s, const char *scene, char *err, size_t errlen)
{
    hsr_status st = hsr_scene_load(scene, &s->sc, err, errlen);
    if (st != HSR_OK) return 1;
    hsr_scene *sc = s->sc;
    int H = sc->height, no = sc->nobj;
    s->base_v = malloc(sizeof(double) * 3 * (size_t)(sc->nv + 1));
    s->off = calloc(3 * (size_t)(no + 1), sizeof(double));
    s->vobj = malloc(sizeof(int) * (size_t)(sc->nv + 1));
    s->ofaces = malloc(sizeof(int) * (size_t)(sc->nf + 1));
    s->ofirst = calloc((size_t)no + 2, sizeof(int));
    s->prev = calloc(3 * (size_t)H, sizeof(yp_cmdlist));
    s->coarse = calloc((size_t)H, 1);
    s->move_ms = calloc((size_t)no + 1, sizeof(double));
    if (!s->move_ms || !s->base_v || !s->off || !s->vobj || !s->ofaces || !s->ofirst || !s->prev || !s->coarse) {
        snprintf(err, errlen, "%s: out of memory", scene);
        return 1;
    }
    memcpy(s->base_v, sc->v, sizeof(double) * 3 * (size_t)sc->nv);
    for (int v = 0; v < sc->nv; v++) s->vobj[v] = -1;
    for (int fi = 0; fi < sc->nf; fi++) {
        s->ofirst[sc->f[fi].obj + 1]++;
        for (int i = 0; i < sc->f[fi].count; i++) s->vobj[sc->fv[sc->f[fi].first + i]] = sc->f[fi].obj;
    }
    for (int o = 0; o < no; o++) s->ofirst[o + 1] += s->ofirst[o];
    int *fill = calloc((size_t)no + 1, sizeof(int));
    if (!fill) { snprintf(err, errlen, "%s: out of memory", scene); return 1; }
    for (int fi = 0; fi < sc->nf; fi++) {
        int o = sc->f[fi].obj;
        s->ofaces[s->ofirst[o] + fill[o]++] = fi;
    }
    free(fill);
    yp_options_default(&s->yo);
    if ((st = yp_shader_new(sc, s->yo.shading, &s->sh, err, errlen)) != HSR_OK) return 1;
    double *shade, t0 = wall_ms();
    if ((st = hsr_scene_build(sc, &s->h, &shade)) != HSR_OK) {
        snprintf(err, errlen, "%s: %s", scene, hsr_status_str(st));
        return 1;
    }
    s->build_ms = wall_ms() - t0;
    free(shade);
    if ((st = yp_frame_new(sc->width, H, &s->fr)) != HSR_OK) { snprintf(err, errlen, "out of memory"); return 1; }
    s->y0 = 0; s->y1 = H;
    return 0;
}

static void server_close(server *s)
{
    if (s->prev && s->sc) for (int i = 0; i < 3 * s->sc->height; i++) yp_cmdlist_free(&s->prev[i]);
    free(s->prev); free(s->coarse); free(s->move_ms);
    yp_frame_free(s->fr); hsr_destroy(s->h); yp_shader_free(s->sh);
    free(s->base_v); free(s->off); free(s->vobj); free(s->ofaces); free(s->ofirst);
    hsr_scene_free(s->sc);
}

static void print_vec(const char *name, const double *v, const char *sep)
{
    printf("\"%s\": [%.17g, %.17g, %.17g]%s", name, v[0], v[1], v[2], sep);
}

static void cmd_info(server *s)
{
    hsr_scene *sc = s->sc;
    hsr_view vw;
    if (!hsr_view_make(sc, &vw)) { reply_error("the camera of the scene is degenerate%s", NULL); return; }
    printf("{\"ok\": true, \"scene\": \"%s\", \"width\": %d, \"height\": %d, \"capacity\": %d, \"faces\": %d, "
           "\"build_ms\": %.3f, ", sc->name, sc->width, sc->height, s->yo.capacity, sc->nf, s->build_ms);
    printf("\"view\": {");
    print_vec("u", vw.u, ", "); print_vec("v", vw.v, ", "); print_vec("w", vw.w, ", ");
    print_vec("eye", sc->eye, ", ");
    printf("\"f\": %.17g}, \"objects\": [", vw.f);
    for (int o = 0; o < sc->nobj; o++) {
        double c[3] = {0, 0, 0};
        long n = 0;
        for (int v = 0; v < sc->nv; v++)
            if (s->vobj[v] == o) { for (int k = 0; k < 3; k++) c[k] += s->base_v[3 * v + k]; n++; }
        for (int k = 0; k < 3; k++) c[k] = n ? c[k] / n : 0;
        int nf = s->ofirst[o + 1] - s->ofirst[o];
        int m = nf ? sc->f[s->ofaces[s->ofirst[o]]].material : 0;
        printf("%s{\"obj\": %d, \"faces\": %d, \"material\": \"%s\", ", o ? ", " : "", o, nf, sc->mat[m].name);
        print_vec("centroid", c, ", ");
        print_vec("offset", &s->off[3 * o], "}");
    }
    printf("], \"materials\": [");
    for (int m = 0; m < sc->nmat; m++)
        printf("%s{\"name\": \"%s\", \"opacity\": %.17g}", m ? ", " : "", sc->mat[m].name, sc->mat[m].opacity);
    printf("], \"lights\": [");
    for (int l = 0; l < sc->nlights; l++) {
        printf("%s{", l ? ", " : "");
        print_vec("dir", sc->lights[l].dir, "}");
    }
    printf("], \"aa\": %d, \"shading\": %d}\n", s->yo.aa, (int)s->yo.shading);
}

static void cmd_pick(server *s, double x, double y)
{
    int id;
    hsr_status st = hsr_pick(s->h, llround(x * HSR_SUBPIXEL), llround(y * HSR_SUBPIXEL), HSR_PICK_VISIBLE, &id);
    if (st == HSR_ENOTFOUND) { printf("{\"ok\": true, \"face\": -1}\n"); return; }
    if (st != HSR_OK) { reply_error("pick failed: %s", hsr_status_str(st)); return; }
    const hsr_scene *sc = s->sc;
    int o = sc->f[id].obj;
    char *mine = calloc((size_t)sc->nf + 1, 1);
    if (!mine) { reply_error("out of memory%s", NULL); return; }
    int64_t bx0 = INT64_MAX, by0 = INT64_MAX, bx1 = INT64_MIN, by1 = INT64_MIN;
    for (int i = s->ofirst[o]; i < s->ofirst[o + 1]; i++) {
        int fi = s->ofaces[i];
        const hsr_domain *d;
        mine[fi] = 1;
        if (!hsr_mlr_get(s->h, fi, &d, NULL, NULL, NULL, NULL) || hsr_domain_is_empty(d)) continue;
        hsr_extent e = hsr_domain_extent(d);
        if (e.left < bx0) bx0 = e.left;
        if (e.bot < by0) by0 = e.bot;
        if (e.right > bx1) bx1 = e.right;
        if (e.top > by1) by1 = e.top;
    }
    double area = 0;
    for (int sl = 0; sl < hsr_llr_slots(s->h); sl++) {
        const hsr_domain *d;
        const int *par;
        int nvis, npar;
        if (!hsr_llr_get(s->h, sl, &d, &par, &nvis, &npar) || nvis < 1) continue;
        if (par[0] >= 0 && par[0] < sc->nf && mine[par[0]]) area += hsr_domain_area(d);
    }
    free(mine);
    double S = HSR_SUBPIXEL;
    printf("{\"ok\": true, \"face\": %d, \"obj\": %d, \"material\": \"%s\", \"visible_area\": %.3f, "
           "\"box\": [%.2f, %.2f, %.2f, %.2f]}\n", id, o, sc->mat[sc->f[id].material].name, area / (S * S),
           bx0 / S, by0 / S, bx1 / S, by1 / S);
}

static void cmd_move(server *s, int o, const double d[3])
{
    hsr_scene *sc = s->sc;
    double t0 = wall_ms();
    for (int k = 0; k < 3; k++) s->off[3 * o + k] = d[k];
    /* base + offset, as yp_anim_apply: the same doubles as a .anim `move` to this offset */
    for (int v = 0; v < sc->nv; v++)
        if (s->vobj[v] == o)
            for (int k = 0; k < 3; k++) sc->v[3 * v + k] = s->base_v[3 * v + k] + d[k];
    hsr_status st = yp_shader_update(s->sh, sc);
    int nf = s->ofirst[o + 1] - s->ofirst[o];
    s->rebuilt = s->move_ms[o] > s->build_ms;
    if (st == HSR_OK && s->rebuilt) {
        double tb = wall_ms();
        st = rebuild(s, o);
        s->build_ms = wall_ms() - tb;
        s->move_ms[o] *= 0.5;
    }
    else if (st == HSR_OK) {
        hsr_view vw;
        if (!hsr_view_make(sc, &vw)) st = HSR_EINVAL;
        /* the object's faces in one hsr_change_many: they leave the LLR together and
         * the damage is repaired once (not once per face as hsr_move would) */
        int cap = hsr_face_cap(sc);
        double *ba = malloc(sizeof(double) * 3 * (size_t)cap), *bb = malloc(sizeof(double) * 3 * (size_t)cap);
        int64_t *q = malloc(sizeof(int64_t) * 2 * (size_t)cap * (size_t)(nf + 1));
        int *len = malloc(sizeof(int) * (size_t)(nf + 1));
        hsr_change *chg = malloc(sizeof(hsr_change) * (size_t)(nf + 1));
        if (!ba || !bb || !q || !len || !chg) st = HSR_ENOMEM;
        for (int k = 0; k < nf && st == HSR_OK; k++) {
            int fi = s->ofaces[s->ofirst[o] + k];
            int64_t *qk = q + 2 * (size_t)cap * (size_t)k;
            hsr_change *c = &chg[k];
            damage_face(s, fi);
            len[k] = hsr_face_project(sc, &vw, fi, ba, bb, qk, &c->plane);
            c->id = fi; c->xy = qk; c->ring_len = &len[k]; c->nrings = 1; c->opacity = -1;
        }
        if (st == HSR_OK && nf) st = hsr_change_many(s->h, chg, nf);
        for (int k = 0; k < nf && st == HSR_OK; k++) damage_face(s, chg[k].id);
        free(ba); free(bb); free(q); free(len); free(chg);
    }
    double ms = wall_ms() - t0;
    if (!s->rebuilt) s->move_ms[o] = ms;
    s->hsr_ms += ms;
    if (st != HSR_OK) { reply_error("move failed: %s", hsr_status_str(st)); return; }
    printf("{\"ok\": true, \"hsr_ms\": %.3f, \"rebuilt\": %s}\n", ms, s->rebuilt ? "true" : "false");
}

static void cmd_opacity(server *s, int m, double a)
{
    hsr_scene *sc = s->sc;
    double t0 = wall_ms();
    sc->mat[m].opacity = a;
    hsr_status st = yp_shader_update(s->sh, sc);
    for (int fi = 0; fi < sc->nf && st == HSR_OK; fi++)
        if (sc->f[fi].material == m) { st = hsr_set_opacity(s->h, fi, a); damage_face(s, fi); }
    double ms = wall_ms() - t0;
    s->hsr_ms += ms;
    if (st != HSR_OK) { reply_error("opacity failed: %s", hsr_status_str(st)); return; }
    printf("{\"ok\": true, \"hsr_ms\": %.3f}\n", ms);
}

static void cmd_light(server *s, int l, const double d[3])
{
    memcpy(s->sc->lights[l].dir, d, sizeof(double) * 3);
    if (l == 0) memcpy(s->sc->light, d, sizeof(double) * 3);
    hsr_status st = yp_shader_update(s->sh, s->sc);
    if (st != HSR_OK) { reply_error("light failed: %s", hsr_status_str(st)); return; }
    damage(s, 0, s->sc->height);      /* every lit pixel may change */
    printf("{\"ok\": true}\n");
}

static int cmd_options(server *s, int aa, yp_shading sh, char *err, size_t errlen)
{
    if (sh != s->yo.shading) {
        yp_shader *n;
        if (yp_shader_new(s->sc, sh, &n, err, errlen) != HSR_OK) return 1;
        yp_shader_free(s->sh);
        s->sh = n;
    }
    s->yo.aa = aa; s->yo.shading = sh;
    damage(s, 0, s->sc->height);
    printf("{\"ok\": true}\n");
    return 0;
}

static int write_changed(server *s, char *const ch[3], int n[3])
{
    static const char nm[] = "rgb";
    int H = s->sc->height, W = s->sc->width;
    yp_cmdlist *view = malloc(sizeof(yp_cmdlist) * (size_t)(H + 1));
    if (!view) return 1;
    for (int c = 0; c < 3; c++) {
        int k = 0;
        for (int y = 0; y < H; y++) if (ch[c][y]) view[k++] = s->fr->line[c * H + y];  /* shallow */
        yp_frame one = {W, k, view, NULL, NULL, {0}, 0, 0, 0, 0};
        char p[4096];
        snprintf(p, sizeof p, "%s/%c.de48", s->dir, nm[c]);
        n[c] = k;
        if (yp_write_de48(&one, 0, p) != HSR_OK) { free(view); return 1; }
    }
    free(view);
    return 0;
}

static void cmd_frame(server *s, int coarse)
{
    int H = s->sc->height;
    yp_options o = s->yo;
    if (coarse) { o.aa = 0; o.shading = YP_FLAT; }
    double t0 = wall_ms();
    int a = s->y0 < s->y1 ? s->y0 : H, b = s->y0 < s->y1 ? s->y1 : 0, refined = 0;
    hsr_status st = HSR_OK;
    /* only the lines scanned now can differ from the lines last sent */
    char *scanned = calloc((size_t)H, 1);
    if (!scanned) { reply_error("out of memory%s", NULL); return; }
    if (a < b) st = yp_scan(s->sh, s->h, &o, a, b, s->fr);
    for (int y = a; y < b; y++) { s->coarse[y] = (char)coarse; scanned[y] = 1; }
    if (!coarse && st == HSR_OK)           /* refine the lines an earlier coarse frame left */
        for (int y = 0; y < H && st == HSR_OK; y++)
            if (s->coarse[y]) {
                int e = y;
                while (e < H && s->coarse[e]) { scanned[e] = 1; s->coarse[e++] = 0; }
                st = yp_scan(s->sh, s->h, &o, y, e, s->fr);
                refined += e - y;
                y = e;
            }
    double t1 = wall_ms();
    if (st != HSR_OK) { free(scanned); reply_error("scan failed: %s", hsr_status_str(st)); return; }
    char *ch[3];
    int nch[3] = {0, 0, 0}, deg = 0, maxslots = 0, over = 0, left = 0;
    for (int c = 0; c < 3; c++) ch[c] = calloc((size_t)H, 1);
    if (!ch[0] || !ch[1] || !ch[2]) {
        for (int c = 0; c < 3; c++) free(ch[c]);
        free(scanned);
        reply_error("out of memory%s", NULL);
        return;
    }
    for (int c = 0; c < 3; c++)
        for (int y = 0; y < H; y++) {
            if (!scanned[y]) continue;
            yp_cmdlist *l = &s->fr->line[c * H + y], *p = &s->prev[c * H + y];
            if (p->c && yp_cmdlist_equal(l, p)) continue;   /* sent */
            ch[c][y] = 1;
            if (l->n > p->cap) {
                yp_cmd *q = realloc(p->c, sizeof(yp_cmd) * (size_t)l->n);
                if (!q) { yp_cmdlist_free(p); continue; }    /* sent again next frame */
                p->c = q; p->cap = l->n;
            }
            memcpy(p->c, l->c, sizeof(yp_cmd) * (size_t)l->n);
            p->n = l->n; p->slots = l->slots;
        }
    free(scanned);
    for (int y = 0; y < H; y++) {
        const yp_line_stats *ls = &s->fr->st[y];
        deg += ls->degraded[0] || ls->degraded[1] || ls->degraded[2];
        over += ls->overflow[0] || ls->overflow[1] || ls->overflow[2];
        for (int c = 0; c < 3; c++) if (ls->slots[c] > maxslots) maxslots = ls->slots[c];
        left += s->coarse[y];
    }
    int rc = write_changed(s, ch, nch);
    double t2 = wall_ms();
    if (rc) { for (int c = 0; c < 3; c++) free(ch[c]); reply_error("%s: cannot write the changed lines", s->dir); return; }
    printf("{\"ok\": true, \"coarse\": %s, \"rescanned\": [%d, %d], \"refined\": %d, \"coarse_lines\": %d, "
           "\"hsr_ms\": %.3f, \"rebuilt\": %s, \"scan_ms\": %.3f, \"write_ms\": %.3f, \"max_slots\": %d, "
           "\"capacity\": %d, \"lines_degraded\": %d, \"lines_overflow\": %d, \"changed\": [",
           coarse ? "true" : "false", a < b ? a : 0, a < b ? b : 0, refined, left, s->hsr_ms,
           s->rebuilt ? "true" : "false", t1 - t0, t2 - t1, maxslots, s->yo.capacity, deg, over);
    for (int c = 0; c < 3; c++) {
        printf("%s[", c ? ", " : "");
        int k = 0;
        for (int y = 0; y < H; y++) if (ch[c][y]) printf("%s%d", k++ ? ", " : "", y);
        printf("]");
        free(ch[c]);
    }
    printf("]}\n");
    s->y0 = s->y1 = 0;
    s->hsr_ms = 0;
    s->rebuilt = 0;
}

static int num(const char *t, double *v) { return t && hsr_text_num(t, v); }

static int index_of(const char *t, int n, int *out)
{
    double v;
    if (!num(t, &v) || v != floor(v) || v < 0 || v >= n) return 0;
    *out = (int)v;
    return 1;
}

/* one request line; returns 1 on quit */
static int handle(server *s, char *line)
{
    char *tok[8];
    const char *p = line;
    char buf[1024];
    int nt = hsr_text_line(&p, buf, sizeof buf, tok, 8);
    char err[1024] = "";
    double v[3];
    int i;
    if (nt < 0) { reply_error("request too long or too many words%s", NULL); return 0; }
    if (nt == 0) { reply_error("empty request%s", NULL); return 0; }
    const char *c = tok[0];
    if (!strcmp(c, "quit")) { printf("{\"ok\": true}\n"); return 1; }
    if (!strcmp(c, "info") && nt == 1) cmd_info(s);
    else if (!strcmp(c, "pick") && nt == 3 && num(tok[1], &v[0]) && num(tok[2], &v[1])) cmd_pick(s, v[0], v[1]);
    else if (!strcmp(c, "move") && nt == 5 && index_of(tok[1], s->sc->nobj, &i)
             && num(tok[2], &v[0]) && num(tok[3], &v[1]) && num(tok[4], &v[2])) cmd_move(s, i, v);
    else if (!strcmp(c, "opacity") && nt == 3 && index_of(tok[1], s->sc->nmat, &i) && num(tok[2], &v[0])
             && v[0] >= 0 && v[0] <= 1) cmd_opacity(s, i, v[0]);
    else if (!strcmp(c, "light") && nt == 5 && index_of(tok[1], s->sc->nlights, &i)
             && num(tok[2], &v[0]) && num(tok[3], &v[1]) && num(tok[4], &v[2])
             && (v[0] != 0 || v[1] != 0 || v[2] != 0)) cmd_light(s, i, v);
    else if (!strcmp(c, "options") && nt == 3 && (!strcmp(tok[1], "0") || !strcmp(tok[1], "1"))
             && (!strcmp(tok[2], "flat") || !strcmp(tok[2], "gouraud") || !strcmp(tok[2], "phong"))) {
        yp_shading sh = tok[2][0] == 'f' ? YP_FLAT : tok[2][0] == 'g' ? YP_GOURAUD : YP_PHONG;
        if (cmd_options(s, tok[1][0] == '1', sh, err, sizeof err)) reply_error("%s", err);
    } else if (!strcmp(c, "frame") && nt == 2 && (!strcmp(tok[1], "full") || !strcmp(tok[1], "coarse")))
        cmd_frame(s, tok[1][0] == 'c');
    else reply_error("malformed request '%s' (info | pick X Y | move OBJ DX DY DZ | opacity MATERIAL A | "
                     "light L DX DY DZ | options 0|1 flat|gouraud|phong | frame full|coarse | quit; "
                     "indices must exist)", c);
    return 0;
}

int yproc_serve_main(int argc, char **argv)
{
    const char *dir = NULL;
    for (int i = 3; i < argc; i++) {
        if (!strcmp(argv[i], "--dir") && i + 1 < argc) dir = argv[++i];
        else return yproc_usage_error("unknown option", argv[i]);
    }
    if (!dir) return yproc_usage_error("missing --dir DIR", NULL);
    server s;
    memset(&s, 0, sizeof s);
    s.dir = dir;
    char err[1024] = "";
    if (server_open(&s, argv[2], err, sizeof err)) {
        fprintf(stderr, "%s\n", err[0] ? err : "yproc serve: cannot open the scene");
        server_close(&s);
        return 1;
    }
    printf("{\"ok\": true, \"ready\": true}\n");
    fflush(stdout);
    char *line = NULL;
    size_t cap = 0;
    while (getline(&line, &cap, stdin) > 0) {
        int q = handle(&s, line);
        fflush(stdout);
        if (q) break;
    }
    free(line);
    server_close(&s);
    return 0;
}
