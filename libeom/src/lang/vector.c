/* vector.c - 3-vectors, 3x3 matrices and rotations, as groups of scalars
 * known when the file is read: each operation expands, while recording,
 * into the scalar operations of its components (a matrix-vector product
 * is nine products and six sums on the tape), through the arithmetic of
 * values with derivatives (tangent.c), so der() of any of them follows.
 * libtape learns nothing new. Matrices are row-major: x[3*i + j] is row
 * i, column j. Shapes were checked when the file was read (shape.c). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "lang.h"

typedef struct ops {
    lang_inst *in;
    int tok;
    int rc; /* -1 after the first failure; later operations do nothing */
} ops;

static ldual dz(void)
{
    ldual z;
    memset(&z, 0, sizeof z);
    z.v.k = 1;
    z.d.k = 1;
    return z;
}

static ldual dnum(double c)
{
    ldual z = dz();
    z.v.c = c;
    return z;
}

static ldual op2(ops *o, int op, ldual a, ldual b)
{
    ldual r = dz();
    if (o->rc == 0 && lang_darith(o->in, op, o->tok, a, b, &r) < 0)
        o->rc = -1;
    return r;
}

static ldual add(ops *o, ldual a, ldual b) { return op2(o, TK_PLUS, a, b); }
static ldual sub(ops *o, ldual a, ldual b) { return op2(o, TK_MINUS, a, b); }
static ldual mul(ops *o, ldual a, ldual b) { return op2(o, TK_STAR, a, b); }
static ldual dvd(ops *o, ldual a, ldual b) { return op2(o, TK_SLASH, a, b); }

static ldual fn1(ops *o, int fn, ldual a)
{
    ldual r = dz();
    if (o->rc == 0 && lang_dfunc(o->in, fn, o->tok, a, dz(), &r) < 0)
        o->rc = -1;
    return r;
}

/* sum_k a[k*sa] * b[k*sb], k = 0..2 */
static ldual dot3(ops *o, const ldual *a, int sa, const ldual *b, int sb)
{
    ldual s = mul(o, a[0], b[0]);
    s = add(o, s, mul(o, a[sa], b[sb]));
    return add(o, s, mul(o, a[2 * sa], b[2 * sb]));
}

static void cross3(ops *o, const ldual *a, const ldual *b, ldual *out)
{
    out[0] = sub(o, mul(o, a[1], b[2]), mul(o, a[2], b[1]));
    out[1] = sub(o, mul(o, a[2], b[0]), mul(o, a[0], b[2]));
    out[2] = sub(o, mul(o, a[0], b[1]), mul(o, a[1], b[0]));
}

int lang_vbinary(lang_inst *in, int op, int tok, const ldvec *a,
                 const ldvec *b, ldvec *out)
{
    ops o = {in, tok, 0};
    int i, j;
    ldvec r;
    if (a->n == 1 && b->n == 1) {
        out->n = 1;
        return lang_darith(in, op, tok, a->x[0], b->x[0], &out->x[0]);
    }
    switch (op) {
    case TK_PLUS:
    case TK_MINUS:
        r.n = a->n;
        for (i = 0; i < a->n; i++)
            r.x[i] = op2(&o, op, a->x[i], b->x[i]);
        break;
    case TK_SLASH: /* by a scalar */
        r.n = a->n;
        for (i = 0; i < a->n; i++)
            r.x[i] = dvd(&o, a->x[i], b->x[0]);
        break;
    default: /* TK_STAR */
        if (a->n == 1 || b->n == 1) {
            const ldvec *s = a->n == 1 ? a : b, *v = a->n == 1 ? b : a;
            r.n = v->n;
            for (i = 0; i < v->n; i++)
                r.x[i] = a->n == 1 ? mul(&o, s->x[0], v->x[i])
                                   : mul(&o, v->x[i], s->x[0]);
        } else if (b->n == SH_VEC) { /* M v */
            r.n = SH_VEC;
            for (i = 0; i < 3; i++)
                r.x[i] = dot3(&o, &a->x[3 * i], 1, b->x, 1);
        } else { /* M N */
            r.n = SH_MAT;
            for (i = 0; i < 3; i++)
                for (j = 0; j < 3; j++)
                    r.x[3 * i + j] = dot3(&o, &a->x[3 * i], 1, &b->x[j], 3);
        }
        break;
    }
    if (o.rc == 0)
        *out = r;
    return o.rc;
}

/* c I + s [n]x + (1 - c) n n^T: a rotation by the angle whose cosine and
 * sine are c and s about the unit axis n (Rodrigues). */
static void rodrigues(ops *o, const ldual *n, ldual c, ldual s, ldual *R)
{
    ldual omc = sub(o, dnum(1.0), c);
    int i, j;
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++) {
            ldual e = mul(o, omc, mul(o, n[i], n[j]));
            if (i == j)
                e = add(o, e, c);
            R[3 * i + j] = e;
        }
    /* the skew part: [n]x = [[0, -nz, ny], [nz, 0, -nx], [-ny, nx, 0]] */
    R[1] = sub(o, R[1], mul(o, s, n[2]));
    R[2] = add(o, R[2], mul(o, s, n[1]));
    R[3] = add(o, R[3], mul(o, s, n[2]));
    R[5] = sub(o, R[5], mul(o, s, n[0]));
    R[6] = sub(o, R[6], mul(o, s, n[1]));
    R[7] = add(o, R[7], mul(o, s, n[0]));
}

/* The rotation of a quaternion (w, x, y, z), divided by its squared
 * norm: a rotation for any nonzero quaternion, the usual formula for a
 * unit one. */
static void quaternion(ops *o, const ldual *q, ldual *R)
{
    ldual w = q[0], x = q[1], y = q[2], z = q[3];
    ldual ww = mul(o, w, w), xx = mul(o, x, x), yy = mul(o, y, y),
          zz = mul(o, z, z);
    ldual n2 = add(o, add(o, ww, xx), add(o, yy, zz));
    lang_inst *in = o->in;
    if (o->rc == 0 && in->quat_check && in->r && !n2.v.k &&
        lang_grow((void **)&in->quat_tok, &in->cap_quat, in->nquat + 1,
                  sizeof *in->quat_tok, 1 << 20) == 0) {
        char name[32];
        snprintf(name, sizeof name, "quat%d", in->nquat + 1);
        if (tp_output(in->r, name, n2.v.v) >= 0)
            in->quat_tok[in->nquat++] = o->tok;
    } else if (o->rc == 0 && n2.v.k && !(fabs(n2.v.c - 1.0) <= 1e-9)) {
        lang_fail(in, o->tok,
                  "a rotation's quaternion (w, x, y, z) has w^2 + x^2 + "
                  "y^2 + z^2 = 1, as cos(a/2), sin(a/2)*axis does",
                  "the quaternion of quat() has length %.17g, not 1",
                  sqrt(n2.v.c));
        o->rc = -1;
    }
    ldual two = dvd(o, dnum(2.0), n2);
    ldual xy = mul(o, x, y), xz = mul(o, x, z), yz = mul(o, y, z),
          wx = mul(o, w, x), wy = mul(o, w, y), wz = mul(o, w, z);
    R[0] = sub(o, dnum(1.0), mul(o, two, add(o, yy, zz)));
    R[4] = sub(o, dnum(1.0), mul(o, two, add(o, xx, zz)));
    R[8] = sub(o, dnum(1.0), mul(o, two, add(o, xx, yy)));
    R[1] = mul(o, two, sub(o, xy, wz));
    R[3] = mul(o, two, add(o, xy, wz));
    R[2] = mul(o, two, add(o, xz, wy));
    R[6] = mul(o, two, sub(o, xz, wy));
    R[5] = mul(o, two, sub(o, yz, wx));
    R[7] = mul(o, two, add(o, yz, wx));
}

/* The angular velocity of R from R and its derivative (the d parts of
 * R's components): the vee of R^T dR/dt in the body, of dR/dt R^T in
 * space. */
static void angvel(ops *o, const ldual *R, int body, ldual *w)
{
    ldual Rv[9], dR[9];
    int k;
    for (k = 0; k < 9; k++) {
        Rv[k] = dz();
        Rv[k].v = R[k].v;
        dR[k] = dz();
        dR[k].v = R[k].d;
    }
    if (body) { /* Omega_ij = sum_k R_ki dR_kj: w = (O_21, O_02, O_10) */
        w[0] = dot3(o, &Rv[2], 3, &dR[1], 3);
        w[1] = dot3(o, &Rv[0], 3, &dR[2], 3);
        w[2] = dot3(o, &Rv[1], 3, &dR[0], 3);
    } else { /* Omega_ij = sum_k dR_ik R_jk */
        w[0] = dot3(o, &dR[6], 1, &Rv[3], 1);
        w[1] = dot3(o, &dR[0], 1, &Rv[6], 1);
        w[2] = dot3(o, &dR[3], 1, &Rv[0], 1);
    }
}

int lang_spatial(lang_inst *in, const node *nd, const ldvec *args,
                 ldvec *out)
{
    ops o = {in, nd->tok, 0};
    ldvec r;
    ldual c, s, n[3], len;
    int i, j;
    memset(&r, 0, sizeof r);
    for (i = 0; i < 9; i++)
        r.x[i] = dz();
    switch (nd->op) {
    case F_VEC:
        r.n = SH_VEC;
        for (i = 0; i < 3; i++)
            r.x[i] = args[0].x[i];
        break;
    case F_MAT:
        r.n = SH_MAT;
        for (i = 0; i < 9; i++)
            r.x[i] = nd->nkids == 9 ? args[0].x[i] : args[i / 3].x[i % 3];
        break;
    case F_DIAG:
        r.n = SH_MAT;
        for (i = 0; i < 3; i++)
            r.x[4 * i] = args[0].x[i];
        break;
    case F_DOT:
        r.n = 1;
        r.x[0] = dot3(&o, args[0].x, 1, args[1].x, 1);
        break;
    case F_CROSS:
        r.n = SH_VEC;
        cross3(&o, args[0].x, args[1].x, r.x);
        break;
    case F_NORM:
        r.n = 1;
        r.x[0] = fn1(&o, F_SQRT, dot3(&o, args[0].x, 1, args[0].x, 1));
        break;
    case F_TRANSPOSE:
        r.n = SH_MAT;
        for (i = 0; i < 3; i++)
            for (j = 0; j < 3; j++)
                r.x[3 * i + j] = args[0].x[3 * j + i];
        break;
    case F_ROTX:
    case F_ROTY:
    case F_ROTZ: {
        /* the axis's own component stays 1; the plane of the other two
         * turns by the angle */
        const int ax = nd->op - F_ROTX, u = (ax + 1) % 3, v = (ax + 2) % 3;
        r.n = SH_MAT;
        c = fn1(&o, F_COS, args[0].x[0]);
        s = fn1(&o, F_SIN, args[0].x[0]);
        r.x[4 * ax] = dnum(1.0);
        r.x[3 * u + u] = c;
        r.x[3 * v + v] = c;
        r.x[3 * u + v] = sub(&o, dz(), s);
        r.x[3 * v + u] = s;
        break;
    }
    case F_ROT:
        r.n = SH_MAT;
        len = fn1(&o, F_SQRT, dot3(&o, args[0].x, 1, args[0].x, 1));
        if (o.rc == 0 && len.v.k && len.v.c == 0.0) {
            lang_fail(in, nd->tok, NULL,
                      "rot() about an axis of length 0");
            return -1;
        }
        for (i = 0; i < 3; i++)
            n[i] = dvd(&o, args[0].x[i], len);
        c = fn1(&o, F_COS, args[1].x[0]);
        s = fn1(&o, F_SIN, args[1].x[0]);
        rodrigues(&o, n, c, s, r.x);
        break;
    case F_QUAT:
        r.n = SH_MAT;
        quaternion(&o, args[0].x, r.x);
        break;
    case F_ANGVEL_BODY:
    case F_ANGVEL_SPACE:
        r.n = SH_VEC;
        angvel(&o, args[0].x, nd->op == F_ANGVEL_BODY, r.x);
        break;
    default:
        lang_fail(in, nd->tok, NULL, "internal error: %s() is not a "
                  "function of vectors", lang_fns[nd->op].name);
        return -1;
    }
    if (o.rc == 0)
        *out = r;
    return o.rc;
}
