/* yp_anim.c - animation scenes (docs/yproc.md): a base scene and, per
 * frame, moves of objects, light directions and material opacities; the
 * frame is applied to the scene and, incrementally, to the HSR (section
 * 5.4.5: move = remove + add, opacity change), reporting the lines whose
 * commands may have changed. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "yp_internal.h"

enum { A_MOVE = 1, A_LIGHT, A_OPACITY };
typedef struct action { int kind, target, f0, f1; double v[3]; } action;

struct yp_anim {
    hsr_scene *sc;
    double *base_v;                    /* world vertices of frame 0 */
    hsr_light base_l[HSR_MAX_LIGHTS];
    double *base_op;                   /* per material */
    action *act; int nact;
    int frames;
    double *cur_off;                   /* per obj: current translation */
    int *vobj;                         /* per vertex: obj index or -1 */
    yp_animx *x;                       /* point lights, wander, textures (yp_tex.c) */
    yp_tess *tess;                     /* coarser versions of objects (yp_tess.c) */
};
yp_tess *yp_anim_tess(yp_anim *a) { return a ? a->tess : NULL; }

int yp_anim_frames(const yp_anim *a) { return a ? a->frames : 0; }
hsr_scene *yp_anim_scene(yp_anim *a) { return a ? a->sc : NULL; }

void yp_anim_free(yp_anim *a)
{
    if (!a) return;
    hsr_scene_free(a->sc);
    free(a->base_v); free(a->base_op); free(a->act); free(a->cur_off); free(a->vobj);
    yp_animx_free(a->x); yp_tess_free(a->tess); free(a);
}

static double ramp(const action *c, int f)
{
    if (f <= c->f0) return 0;
    if (f >= c->f1) return 1;
    return (double)(f - c->f0) / (c->f1 - c->f0);
}

hsr_status yp_anim_load(const char *path, yp_anim **out, char *err, size_t errlen)
{
    if (!path || !out) return HSR_EINVAL;
    *out = NULL;
    /* the whole file, then line by line: a line too long for the buffer is an error,
     * not two lines (fgets would split it silently) */
    char *f;
    hsr_status rs = hsr_read_text_file(path, &f);
    if (rs != HSR_OK) { if (err) snprintf(err, errlen, "%s: cannot read (%s)", path, hsr_status_str(rs)); return rs; }
    yp_anim *a = calloc(1, sizeof *a);
    if (!a) { free(f); return HSR_ENOMEM; }
    a->frames = 1;
    char line[4096], dir[1024];
    snprintf(dir, sizeof dir, "%s", path);
    char *sl = strrchr(dir, '/');
    if (sl) *sl = 0; else snprintf(dir, sizeof dir, ".");
    int lineno = 0;
    hsr_status st = HSR_OK;
#define AFAIL(...) do { if (err) { int k_ = snprintf(err, errlen, "%s:%d: ", path, lineno); \
    if (k_ >= 0 && (size_t)k_ < errlen) snprintf(err + k_, errlen - (size_t)k_, __VA_ARGS__); } st = HSR_EPARSE; goto fail; } while (0)
    const char *text = f;
    while (*text) {
        lineno++;
        char *tok[16];
        int nt = hsr_text_line(&text, line, sizeof line, tok, 16);
        if (nt == -1) AFAIL("line too long");
        if (nt < 0) AFAIL("too many items");
        if (nt == 0) continue;
        if (!strcmp(tok[0], "scene")) {
            if (nt != 2 || a->sc) AFAIL("expected one 'scene FILE'");
            char p[2048];
            if (tok[1][0] == '/') snprintf(p, sizeof p, "%s", tok[1]); else snprintf(p, sizeof p, "%s/%s", dir, tok[1]);
            /* a scene that cannot be opened is this line's error (the scene's own errors
             * name the scene file and its line) */
            FILE *sf = fopen(p, "rb");
            if (!sf) AFAIL("cannot read scene file '%s' (%s)", p, hsr_status_str(HSR_EIO));
            fclose(sf);
            st = hsr_scene_load(p, &a->sc, err, errlen);
            if (st != HSR_OK) goto fail;
        } else if (!strcmp(tok[0], "frames")) {
            double v;
            if (nt != 2 || !hsr_text_num(tok[1], &v) || v < 1 || v > 100000 || v != (int)v) AFAIL("'frames N' needs an integer >= 1");
            a->frames = (int)v;
        } else if (!strcmp(tok[0], "move") || !strcmp(tok[0], "light") || !strcmp(tok[0], "opacity")) {
            /* move OBJ DX DY DZ from F0 to F1 | light L DX DY DZ from F0 to F1 | opacity MATERIAL A from F0 to F1 */
            int isop = !strcmp(tok[0], "opacity"), nv = isop ? 1 : 3;
            if (!a->sc) AFAIL("'scene FILE' must come first");
            if (nt != 2 + nv + 4 || strcmp(tok[2 + nv], "from") || strcmp(tok[4 + nv], "to"))
                AFAIL("expected '%s %s from F0 to F1'", tok[0], isop ? "MATERIAL A" : tok[0][0] == 'm' ? "OBJ DX DY DZ" : "L DX DY DZ");
            action c = {0};
            c.kind = isop ? A_OPACITY : tok[0][0] == 'm' ? A_MOVE : A_LIGHT;
            double fv[2], t;
            if (!hsr_text_num(tok[3 + nv], &fv[0]) || !hsr_text_num(tok[5 + nv], &fv[1]) || fv[0] < 0 || fv[1] <= fv[0])
                AFAIL("frame range must be 0 <= F0 < F1");
            c.f0 = (int)fv[0]; c.f1 = (int)fv[1];
            for (int i = 0; i < nv; i++) if (!hsr_text_num(tok[2 + i], &c.v[i])) AFAIL("bad number '%s'", tok[2 + i]);
            if (c.kind == A_OPACITY) {
                c.target = -1;
                for (int i = 0; i < a->sc->nmat; i++) if (!strcmp(a->sc->mat[i].name, tok[1])) c.target = i;
                if (c.target < 0) AFAIL("unknown material '%s'", tok[1]);
                if (!(c.v[0] >= 0 && c.v[0] <= 1)) AFAIL("opacity must be in [0,1]");
            } else {
                if (!hsr_text_num(tok[1], &t) || t < 0 || t != (int)t) AFAIL("bad index '%s'", tok[1]);
                c.target = (int)t;
                if (c.kind == A_MOVE && c.target >= a->sc->nobj) AFAIL("object %d does not exist (%d obj lines)", c.target, a->sc->nobj);
                if (c.kind == A_LIGHT && c.target >= a->sc->nlights) AFAIL("light %d does not exist", c.target);
                if (c.kind == A_LIGHT && c.v[0] == 0 && c.v[1] == 0 && c.v[2] == 0) AFAIL("light direction is zero");
            }
            action *p = realloc(a->act, sizeof(action) * (size_t)(a->nact + 1));
            if (!p) { st = HSR_ENOMEM; goto fail; }
            a->act = p; a->act[a->nact++] = c;
        } else {
            char m[512];
            int r = a->sc ? yp_animx_parse(&a->x, a->sc, tok, nt, m, sizeof m) : 0;
            if (r == 0 && a->sc) r = yp_tess_parse(&a->tess, a->sc, tok, nt, m, sizeof m);
            if (r < 0) AFAIL("%s", m);
            if (r == 0) AFAIL("unknown statement '%s'", tok[0]);
        }
    }
    if (!a->sc) AFAIL("no 'scene FILE'");
    free(f); f = NULL;
    hsr_scene *sc = a->sc;
    a->base_v = malloc(sizeof(double) * 3 * (size_t)(sc->nv + 1));
    a->base_op = malloc(sizeof(double) * (size_t)(sc->nmat + 1));
    a->cur_off = calloc(3 * (size_t)(sc->nobj + 1), sizeof(double));
    a->vobj = malloc(sizeof(int) * (size_t)(sc->nv + 1));
    if (!a->base_v || !a->base_op || !a->cur_off || !a->vobj) { st = HSR_ENOMEM; goto fail; }
    memcpy(a->base_v, sc->v, sizeof(double) * 3 * (size_t)sc->nv);
    for (int i = 0; i < sc->nmat; i++) a->base_op[i] = sc->mat[i].opacity;
    memcpy(a->base_l, sc->lights, sizeof a->base_l);
    for (int v = 0; v < sc->nv; v++) a->vobj[v] = -1;
    for (int fi = 0; fi < sc->nf; fi++)
        for (int i = 0; i < sc->f[fi].count; i++) a->vobj[sc->fv[sc->f[fi].first + i]] = sc->f[fi].obj;
    *out = a;
    return HSR_OK;
fail:
    free(f);
    yp_anim_free(a);
    return st;
#undef AFAIL
}

static void extent_rows(const hsr_ctx *h, int id, int H, int *y0, int *y1)
{
    const hsr_domain *d;
    if (!hsr_mlr_get(h, id, &d, NULL, NULL, NULL, NULL) || hsr_domain_is_empty(d)) return;
    hsr_extent e = hsr_domain_extent(d);
    int a = (int)floor((double)e.bot / HSR_SUBPIXEL), b = (int)ceil((double)e.top / HSR_SUBPIXEL) + 1;
    if (a < 0) a = 0;
    if (b > H) b = H;
    if (a < *y0) *y0 = a;
    if (b > *y1) *y1 = b;
}

hsr_status yp_anim_apply(yp_anim *a, int fr, hsr_ctx *h, yp_shader *sh, int *y0, int *y1)
{
    if (!a) return HSR_EINVAL;
    hsr_scene *sc = a->sc;
    int H = sc->height, ly0 = H, ly1 = 0, lights = 0;
    hsr_status st = HSR_OK;
    /* object translations */
    double *off = calloc(3 * (size_t)(sc->nobj + 1), sizeof(double));
    char *moved = calloc((size_t)sc->nobj + 1, 1);
    if (!off || !moved) { free(off); free(moved); return HSR_ENOMEM; }
    for (int i = 0; i < a->nact; i++) {
        const action *c = &a->act[i];
        double r = ramp(c, fr);
        if (c->kind == A_MOVE) for (int k = 0; k < 3; k++) off[3 * c->target + k] += r * c->v[k];
    }
    yp_tess_offsets(a->tess, sc, off);   /* the versions shown and parked */
    for (int o = 0; o < sc->nobj; o++)
        for (int k = 0; k < 3; k++) if (off[3 * o + k] != a->cur_off[3 * o + k]) moved[o] = 1;
    for (int v = 0; v < sc->nv; v++) {
        int o = a->vobj[v];
        for (int k = 0; k < 3; k++) sc->v[3 * v + k] = a->base_v[3 * v + k] + (o >= 0 ? off[3 * o + k] : 0);
    }
    memcpy(a->cur_off, off, sizeof(double) * 3 * (size_t)sc->nobj);
    /* lights and opacities */
    hsr_light old_l[HSR_MAX_LIGHTS];
    memcpy(old_l, sc->lights, sizeof old_l);
    memcpy(sc->lights, a->base_l, sizeof old_l);
    double *old_op = malloc(sizeof(double) * (size_t)(sc->nmat + 1));
    if (!old_op) { free(off); free(moved); return HSR_ENOMEM; }
    for (int m = 0; m < sc->nmat; m++) { old_op[m] = sc->mat[m].opacity; sc->mat[m].opacity = a->base_op[m]; }
    for (int i = 0; i < a->nact; i++) {
        const action *c = &a->act[i];
        double r = ramp(c, fr);
        if (c->kind == A_LIGHT) {
            double *d = sc->lights[c->target].dir, b[3], t[3] = {c->v[0], c->v[1], c->v[2]};
            memcpy(b, a->base_l[c->target].dir, sizeof b);
            double lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]), lt = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
            for (int k = 0; k < 3; k++) d[k] = (1 - r) * b[k] / lb + r * t[k] / lt;
        } else if (c->kind == A_OPACITY)
            sc->mat[c->target].opacity = (1 - r) * a->base_op[c->target] + r * c->v[0];
    }
    for (int l = 0; l < sc->nlights; l++)
        for (int k = 0; k < 3; k++) if (sc->lights[l].dir[k] != old_l[l].dir[k]) lights = 1;
    if (sh) st = yp_shader_update(sh, sc);
    if (sh && st == HSR_OK) lights |= yp_animx_apply(a->x, fr, sh, &st);
    if (h && st == HSR_OK) {
        /* every moved face and changed opacity of the frame in one hsr_change_many:
         * one damage repair for all of them (docs/hsr.md, "Damage repair") */
        hsr_view vw;
        if (!hsr_view_make(sc, &vw)) st = HSR_EINVAL;
        int cap = hsr_face_cap(sc), nc = 0, nq = 0;
        for (int fi = 0; fi < sc->nf; fi++) nq += moved[sc->f[fi].obj];
        double *ba = malloc(sizeof(double) * 3 * (size_t)cap), *bb = malloc(sizeof(double) * 3 * (size_t)cap);
        int64_t *q = malloc(sizeof(int64_t) * 2 * (size_t)cap * (size_t)(nq + 1));
        int *len = malloc(sizeof(int) * (size_t)(nq + 1));
        hsr_change *chg = malloc(sizeof(hsr_change) * (size_t)(sc->nf + 1));
        if (!ba || !bb || !q || !len || !chg) st = HSR_ENOMEM;
        for (int fi = 0, k = 0; fi < sc->nf && st == HSR_OK; fi++) {
            int m = sc->f[fi].material, mv = moved[sc->f[fi].obj], op = sc->mat[m].opacity != old_op[m];
            if (!mv && !op) continue;
            hsr_change *c = &chg[nc++];
            c->id = fi; c->xy = NULL; c->ring_len = NULL; c->nrings = 0;
            c->plane = (hsr_plane){0, 0, 0};
            c->opacity = op ? sc->mat[m].opacity : -1;
            extent_rows(h, fi, H, &ly0, &ly1);
            if (mv) {
                int64_t *qk = q + 2 * (size_t)cap * (size_t)k;
                len[k] = hsr_face_project(sc, &vw, fi, ba, bb, qk, &c->plane);
                c->xy = qk; c->ring_len = &len[k]; c->nrings = 1;
                k++;
            }
        }
        if (st == HSR_OK && nc) st = hsr_change_many(h, chg, nc);
        for (int i = 0; i < nc && st == HSR_OK; i++) extent_rows(h, chg[i].id, H, &ly0, &ly1);
        free(ba); free(bb); free(q); free(len); free(chg);
    }
    if (lights) { ly0 = 0; ly1 = H; }
    if (ly0 > ly1) ly0 = ly1 = 0;
    if (y0) *y0 = ly0;
    if (y1) *y1 = ly1;
    free(off); free(moved); free(old_op);
    return st;
}

int yp_cmdlist_equal(const yp_cmdlist *a, const yp_cmdlist *b)
{
    if (a->n != b->n) return 0;
    for (int i = 0; i < a->n; i++) {
        const yp_cmd *p = &a->c[i], *q = &b->c[i];
        if (p->op != q->op || p->order != q->order || p->x != q->x || p->dx != q->dx
            || p->v[0] != q->v[0] || p->v[1] != q->v[1] || p->v[2] != q->v[2]) return 0;
    }
    return 1;
}
