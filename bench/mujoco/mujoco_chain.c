/* mujoco_chain.c - the rigid chain as a model built in memory (URDF, which
 * MuJoCo reads beside MJCF) and loaded through MuJoCo's virtual file
 * system (see mujoco_chain.h). */
#include "mujoco_chain.h"

#include <math.h>
#include <mujoco/mujoco.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct mujoco_chain {
    int N;
    mjModel *m;
    mjData *d;
};

/* Append to buf (size cap, used *len); 0, or -1 when it is full. */
static int put(char *buf, size_t cap, size_t *len, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static int put(char *buf, size_t cap, size_t *len, const char *fmt, ...)
{
    va_list ap;
    int k;
    va_start(ap, fmt);
    k = vsnprintf(buf + *len, cap - *len, fmt, ap);
    va_end(ap);
    if (k < 0 || (size_t)k >= cap - *len)
        return -1;
    *len += (size_t)k;
    return 0;
}

/* The model as URDF, which MuJoCo compiles into the same kinematic tree
 * as the nested MJCF bodies it replaced: MJCF nests each link inside the
 * one before, and MuJoCo's XML reader (TinyXML-2) refuses elements nested
 * deeper than 100, about 97 links; URDF lists links and joints side by
 * side. Link j hangs at the tip of link j - 1 (x = L[j-1] in its frame);
 * its hinge turns about -y, so a positive angle turns +x towards +z (our
 * +y); the rod's centre of mass is at L/2 on its x axis, its inertia
 * about the hinge's axis m L^2 / 12 at the centre (the other two axes
 * only need to be positive). The massless base link is fused into the
 * world; gravity and the disabled contacts are set on the compiled
 * model (mujoco_chain_new). */
static char *urdf(int N, const double *m, const double *L)
{
    const size_t cap = 4096 + (size_t)N * 1024;
    char *buf = malloc(cap);
    size_t len = 0;
    int j, bad = 0;
    if (!buf)
        return NULL;
    bad |= put(buf, cap, &len,
               "<robot name=\"chain\">\n"
               "  <mujoco>\n"
               "    <compiler angle=\"radian\" fusestatic=\"true\"/>\n"
               "  </mujoco>\n"
               "  <link name=\"base\"/>\n");
    for (j = 0; j < N; j++) {
        const double I = m[j] * L[j] * L[j] / 12.0;
        char parent[32] = "base";
        if (j)
            snprintf(parent, sizeof parent, "link%d", j);
        bad |= put(buf, cap, &len,
                   "  <link name=\"link%d\">\n"
                   "    <inertial>\n"
                   "      <origin xyz=\"%.17g 0 0\" rpy=\"0 0 0\"/>\n"
                   "      <mass value=\"%.17g\"/>\n"
                   "      <inertia ixx=\"%.17g\" iyy=\"%.17g\" "
                   "izz=\"%.17g\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/>\n"
                   "    </inertial>\n"
                   "  </link>\n"
                   "  <joint name=\"hinge%d\" type=\"continuous\">\n"
                   "    <parent link=\"%s\"/>\n"
                   "    <child link=\"link%d\"/>\n"
                   "    <origin xyz=\"%.17g 0 0\" rpy=\"0 0 0\"/>\n"
                   "    <axis xyz=\"0 -1 0\"/>\n"
                   "  </joint>\n",
                   j + 1, 0.5 * L[j], m[j], 1e-6 * I, I, I, j + 1,
                   parent, j + 1, j ? L[j - 1] : 0.0);
    }
    bad |= put(buf, cap, &len, "</robot>\n");
    if (bad) {
        free(buf);
        return NULL;
    }
    return buf;
}

mujoco_chain *mujoco_chain_new(int N, const double *m, const double *L,
                               double g, char *err, int errlen)
{
    mujoco_chain *c = calloc(1, sizeof *c);
    mjVFS *vfs = malloc(sizeof *vfs);
    char *text = urdf(N, m, L);
    int k;
    if (!c || !vfs || !text) {
        snprintf(err, (size_t)errlen, "out of memory");
        goto fail;
    }
    mj_defaultVFS(vfs);
    if (mj_makeEmptyFileVFS(vfs, "chain.xml", (int)strlen(text)) != 0 ||
        (k = mj_findFileVFS(vfs, "chain.xml")) < 0) {
        snprintf(err, (size_t)errlen, "MuJoCo's file system took no file");
        goto fail;
    }
    memcpy(vfs->filedata[k], text, strlen(text));
    c->m = mj_loadXML("chain.xml", vfs, err, errlen);
    mj_deleteVFS(vfs);
    free(vfs);
    vfs = NULL;
    if (!c->m)
        goto fail;
    c->m->opt.gravity[0] = c->m->opt.gravity[1] = 0.0;
    c->m->opt.gravity[2] = -g;
    c->m->opt.disableflags |= mjDSBL_CONTACT;
    if (c->m->nv != N) {
        snprintf(err, (size_t)errlen, "the model has %d degrees of "
                 "freedom, not %d", c->m->nv, N);
        goto fail;
    }
    c->d = mj_makeData(c->m);
    if (!c->d) {
        snprintf(err, (size_t)errlen, "mj_makeData failed");
        goto fail;
    }
    c->N = N;
    free(text);
    return c;
fail:
    if (vfs) {
        mj_deleteVFS(vfs);
        free(vfs);
    }
    free(text);
    mujoco_chain_free(c);
    return NULL;
}

void mujoco_chain_free(mujoco_chain *c)
{
    if (!c)
        return;
    if (c->d)
        mj_deleteData(c->d);
    if (c->m)
        mj_deleteModel(c->m);
    free(c);
}

void mujoco_chain_set(mujoco_chain *c, const double *x)
{
    int j;
    for (j = 0; j < c->N; j++) {
        c->d->qpos[j] = x[j] - (j ? x[j - 1] : 0.0);
        c->d->qvel[j] = x[c->N + j] - (j ? x[c->N + j - 1] : 0.0);
    }
}

void mujoco_chain_forward(mujoco_chain *c)
{
    mj_forward(c->m, c->d);
}

void mujoco_chain_qdd(const mujoco_chain *c, double *qdd)
{
    double sum = 0.0;
    int j;
    for (j = 0; j < c->N; j++) {
        sum += c->d->qacc[j];
        qdd[j] = sum;
    }
}

double mujoco_chain_backward_error(const mujoco_chain *c, const double *qdd)
{
    const int N = c->N;
    double *M = malloc((size_t)N * (size_t)N * sizeof(double));
    double d = 0.0, Mmax = 0.0, amax = 0.0;
    int i, k;
    if (!M)
        return INFINITY;
    mj_fullM(c->m, M, c->d->qM);
    for (i = 0; i < N; i++) {
        double r = 0.0;
        for (k = 0; k < N; k++) {
            /* qdd's hinge acceleration: relative to the parent link */
            const double rel = qdd[k] - (k ? qdd[k - 1] : 0.0);
            r += M[i * N + k] * (c->d->qacc[k] - rel);
            Mmax = fmax(Mmax, fabs(M[i * N + k]));
        }
        d = fmax(d, fabs(r));
        amax = fmax(amax, fabs(c->d->qacc[i]));
    }
    free(M);
    return d / (Mmax * amax > 0.0 ? Mmax * amax : 1.0);
}
