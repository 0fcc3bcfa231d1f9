/* mujoco_chain.h - the rigid chain of the element library (eom/chain.h:
 * links from +x, counter-clockwise angles, gravity along -y) as a MuJoCo
 * model, for the benchmarks: the chain's plane is MuJoCo's x-z plane
 * (our y is its z, so its default gravity is ours), each link a body on
 * a hinge about -y at the tip of the one before, with the inertia of a
 * uniform rod given explicitly, contacts disabled. MuJoCo's hinge angles
 * are relative to the parent link; these calls take and give the chain's
 * absolute angles. */
#ifndef BENCH_MUJOCO_CHAIN_H
#define BENCH_MUJOCO_CHAIN_H

typedef struct mujoco_chain mujoco_chain;

/* N links of masses m[j] and lengths L[j], gravity g. On failure NULL,
 * with a reason in err. */
mujoco_chain *mujoco_chain_new(int N, const double *m, const double *L,
                               double g, char *err, int errlen);
void mujoco_chain_free(mujoco_chain *c);

/* Set the state x = (theta, theta_dot) (absolute angles). */
void mujoco_chain_set(mujoco_chain *c, const double *x);
/* mj_forward at the state set; the absolute accelerations in qdd (N). */
void mujoco_chain_forward(mujoco_chain *c);
void mujoco_chain_qdd(const mujoco_chain *c, double *qdd);
/* The backward error of other absolute accelerations qdd (N) in MuJoCo's
 * own equations at the last forward: |M_h (qacc - qdd_h)| / (|M_h| |qacc|)
 * in max norms, with MuJoCo's mass matrix M_h and qdd_h qdd's hinge
 * (relative) accelerations. INFINITY out of memory. */
double mujoco_chain_backward_error(const mujoco_chain *c, const double *qdd);

#endif
