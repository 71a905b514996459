/* symbols.c -- the scene reader's values and identifier scopes.
 *
 * Scope 0 is global; every include file and macro call pushes one more.
 * Lookup goes from the innermost scope out.  #local sets a name in the
 * innermost scope; #declare changes the innermost existing definition, or
 * makes a global one (POV-Ray's rules).  Each scope is an open-addressing
 * hash table (FNV-1a).  Values own what they point to. */
#include <stdlib.h>
#include <string.h>

#include "csg.h"
#include "parse_internal.h"

static void group_init(rs_group *g)
{
    memset(g, 0, sizeof *g);
}

void rs__group_free(rs_group *g)
{
    for (size_t i = 0; i < g->n_objects; i++)
        rs_object_release(&g->objects[i]);
    free(g->objects);
    free(g->lights);
    group_init(g);
}

int rs__group_push_object(rs_group *g, const rs_object *o)
{
    if (g->n_objects == g->cap_objects) {
        size_t cap = g->cap_objects ? 2 * g->cap_objects : 4;
        rs_object *a = realloc(g->objects, cap * sizeof *a);
        if (a == NULL)
            return -1;
        g->objects = a;
        g->cap_objects = cap;
    }
    if (rs_object_copy(&g->objects[g->n_objects], o) != 0)
        return -1;
    g->n_objects++;
    return 0;
}

int rs__group_push_light(rs_group *g, const rs_light *l)
{
    if (g->n_lights == g->cap_lights) {
        size_t cap = g->cap_lights ? 2 * g->cap_lights : 2;
        rs_light *a = realloc(g->lights, cap * sizeof *a);
        if (a == NULL)
            return -1;
        g->lights = a;
        g->cap_lights = cap;
    }
    g->lights[g->n_lights++] = *l;
    return 0;
}

int rs__group_append(rs_group *dst, const rs_group *src)
{
    for (size_t i = 0; i < src->n_objects; i++)
        if (rs__group_push_object(dst, &src->objects[i]) != 0)
            return -1;
    for (size_t i = 0; i < src->n_lights; i++)
        if (rs__group_push_light(dst, &src->lights[i]) != 0)
            return -1;
    return 0;
}

void rs__val_free(val *v)
{
    free(v->str);
    if (v->kind == VAL_OBJECT && v->ptr != NULL)
        rs__group_free(v->ptr);
    free(v->ptr);
    v->str = NULL;
    v->ptr = NULL;
}

static size_t payload_size(val_kind k)
{
    switch (k) {
    case VAL_PIGMENT: return sizeof(rs_pigment_val);
    case VAL_FINISH: return sizeof(rs_finish);
    case VAL_TEXTURE: return sizeof(rs_texture_val);
    case VAL_INTERIOR: return sizeof(double);
    case VAL_OBJECT: return sizeof(rs_group);
    default: return 0;
    }
}

int rs__val_copy(const val *src, val *dst)
{
    *dst = *src;
    dst->str = NULL;
    dst->ptr = NULL;
    if (src->str != NULL) {
        size_t n = strlen(src->str);
        if ((dst->str = malloc(n + 1)) == NULL)
            return -1;
        memcpy(dst->str, src->str, n + 1);
    }
    if (src->ptr != NULL) {
        size_t n = payload_size(src->kind);
        if ((dst->ptr = malloc(n)) == NULL) {
            rs__val_free(dst);
            return -1;
        }
        if (src->kind == VAL_OBJECT) {
            group_init(dst->ptr);
            if (rs__group_append(dst->ptr, src->ptr) != 0) {
                rs__val_free(dst);
                return -1;
            }
        } else {
            memcpy(dst->ptr, src->ptr, n);
        }
    }
    return 0;
}

static size_t hash_name(const char *s, size_t n)
{
    size_t h = (size_t)1469598103934665603ull;
    for (size_t i = 0; i < n; i++) {
        h ^= (unsigned char)s[i];
        h *= (size_t)1099511628211ull;
    }
    return h;
}

static sym *scope_find(scope *s, const char *name, size_t len)
{
    size_t i;
    if (s->cap == 0)
        return NULL;
    i = hash_name(name, len) & (s->cap - 1);
    while (s->syms[i].name != NULL) {
        if (s->syms[i].len == len && memcmp(s->syms[i].name, name, len) == 0)
            return &s->syms[i];
        i = (i + 1) & (s->cap - 1);
    }
    return NULL;
}

/* Rebuild the table with room for one more (also drops deleted slots). */
static int scope_rehash(scope *s, size_t cap)
{
    sym *a = calloc(cap, sizeof *a);
    if (a == NULL)
        return -1;
    for (size_t k = 0; k < s->cap; k++) {
        if (s->syms[k].name != NULL) {
            size_t i = hash_name(s->syms[k].name, s->syms[k].len) & (cap - 1);
            while (a[i].name != NULL)
                i = (i + 1) & (cap - 1);
            a[i] = s->syms[k];
        }
    }
    free(s->syms);
    s->syms = a;
    s->cap = cap;
    return 0;
}

static void scope_free(scope *s)
{
    for (size_t i = 0; i < s->cap; i++) {
        if (s->syms[i].name != NULL) {
            free(s->syms[i].name);
            rs__val_free(&s->syms[i].v);
        }
    }
    free(s->syms);
    memset(s, 0, sizeof *s);
}

int rs__scope_push(parser *p)
{
    if (p->n_scopes == p->cap_scopes) {
        size_t cap = p->cap_scopes ? 2 * p->cap_scopes : 8;
        scope *a = realloc(p->scopes, cap * sizeof *a);
        if (a == NULL)
            return -1;
        p->scopes = a;
        p->cap_scopes = cap;
    }
    memset(&p->scopes[p->n_scopes++], 0, sizeof(scope));
    return 0;
}

void rs__scope_pop(parser *p)
{
    if (p->n_scopes > 0)
        scope_free(&p->scopes[--p->n_scopes]);
}

sym *rs__sym_find(parser *p, const char *name, size_t len)
{
    for (size_t k = p->n_scopes; k-- > 0;) {
        sym *s = scope_find(&p->scopes[k], name, len);
        if (s != NULL)
            return s;
    }
    return NULL;
}

int rs__sym_set(parser *p, const char *name, size_t len, val *v, int local)
{
    scope *sc;
    sym *s;
    size_t i;

    if (p->n_scopes == 0 && rs__scope_push(p) != 0)
        return -1;
    if (local) {
        sc = &p->scopes[p->n_scopes - 1];
        s = scope_find(sc, name, len);
    } else {
        s = rs__sym_find(p, name, len);
        sc = &p->scopes[0];
    }
    if (s != NULL) {
        rs__val_free(&s->v);
        s->v = *v;
        memset(v, 0, sizeof *v);
        return 0;
    }
    if ((sc->count + 1) * 10 > sc->cap * 7 && scope_rehash(sc, sc->cap ? 2 * sc->cap : 16) != 0)
        return -1;
    i = hash_name(name, len) & (sc->cap - 1);
    while (sc->syms[i].name != NULL)
        i = (i + 1) & (sc->cap - 1);
    if ((sc->syms[i].name = malloc(len + 1)) == NULL)
        return -1;
    memcpy(sc->syms[i].name, name, len);
    sc->syms[i].name[len] = '\0';
    sc->syms[i].len = len;
    sc->syms[i].v = *v;
    memset(v, 0, sizeof *v);
    sc->count++;
    return 0;
}

/* Remove the innermost definition of name (returns 1 if there was one). */
int rs__sym_undef(parser *p, const char *name, size_t len)
{
    for (size_t k = p->n_scopes; k-- > 0;) {
        scope *sc = &p->scopes[k];
        sym *s = scope_find(sc, name, len);
        if (s != NULL) {
            free(s->name);
            rs__val_free(&s->v);
            s->name = NULL;
            sc->count--;
            /* Re-insert the cluster after the hole (linear probing). */
            if (scope_rehash(sc, sc->cap) != 0)
                return -1;
            return 1;
        }
    }
    return 0;
}

const macro *rs__macro_find(const parser *p, const char *name, size_t len)
{
    for (size_t i = 0; i < p->n_macros; i++)
        if (p->macros[i].len == len && memcmp(p->macros[i].name, name, len) == 0)
            return &p->macros[i];
    return NULL;
}

void rs__symbols_free(parser *p)
{
    while (p->n_scopes > 0)
        rs__scope_pop(p);
    free(p->scopes);
    p->scopes = NULL;
    p->cap_scopes = 0;
    for (size_t i = 0; i < p->n_macros; i++) {
        free(p->macros[i].name);
        for (int k = 0; k < p->macros[i].n_params; k++)
            free(p->macros[i].params[k]);
    }
    free(p->macros);
    p->macros = NULL;
    p->n_macros = p->cap_macros = 0;
}
