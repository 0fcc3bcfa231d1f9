/* chain.h - element library: planar chains of rigid and flexible links.
 *
 * A chain of N links hangs from a pin at the origin; with closed set, its
 * tip is pinned at (D, 0) too. Link j has an absolute chord angle theta_j
 * (from +x, counter-clockwise), length L_j, mass m_j (uniform density
 * rho_j = m_j / L_j) and bending stiffness EI_j. A flexible link carries K_j
 * assumed modes: its transverse deflection is
 *     v_j(x, t) = sum_i q_{j,i}(t) sin(i pi x / L_j),   i = 1 .. K_j,
 * which vanishes at both joints (K_j = 0: a rigid link). The energies use
 * the closed-form modal integrals (docs/elements.md) and the kinetic
 * energy is accumulated joint by joint, so the tape grows linearly with
 * the number of links. Gravity acts along -y.
 *
 * eom_chain_add adds to a model, with names prefixed by spec->prefix:
 *   coordinates  theta1 .. thetaN (rad), qJ_I (m: mode I of link J)
 *   parameters   mJ (kg), LJ (m), EIJ (N m^2) for every link J; g (m/s^2);
 *                c (N m s/rad) when some joint has a damper; k (N m/rad)
 *                when some joint has a spring; D (m) for a closed chain;
 *                zeta, ray_a (1/s) and ray_b (s) with structural damping
 *   energies     T (kinetic), V (strain + gravity + springs), R (dampers,
 *                structural damping)
 *   constraints  sum L_j cos theta_j - D = 0, sum L_j sin theta_j = 0
 *                (closed chains)
 *   probes       TJ_rigid (the link's kinetic energy as a rigid rod of its
 *                chord), TJ_flex (the rest of its kinetic energy), UJ_strain
 *                (its strain energy), all in J
 * Joints are numbered 0 (ground to link 1), j (link j to link j+1) and N
 * (link N to the ground pin of a closed chain); a damper at joint j adds
 * 1/2 c (relative rate)^2 to R, a spring 1/2 k (relative angle)^2 to V.
 *
 * Structural damping acts on the flexible coordinates only, never on the
 * angles: mode i of link j, with modal mass m_j / 2 and modal stiffness
 * k_ji = EI_j (i pi)^4 / (2 L_j^3), gets the damping coefficient
 *     c_ji = 2 zeta sqrt(k_ji m_j / 2) + ray_a m_j / 2 + ray_b k_ji,
 * a modal damping ratio zeta (the same for every mode) plus Rayleigh
 * damping a M + b K of the link's own modal block, and adds
 * 1/2 c_ji (dq_ji/dt)^2 to R, so E + W still balances. All three default
 * to 0, the paper's undamped beams (docs/elements.md).
 */
#ifndef EOM_CHAIN_H
#define EOM_CHAIN_H

#include "eom/eom.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct eom_chain_spec {
    int links;            /* N >= 1 */
    const int *modes;     /* [N] modes per link (0: rigid); NULL: all use
                             modes_all */
    int modes_all;
    int closed;           /* pin the tip at (D, 0) */
    const char *prefix;   /* prepended to every name; NULL: none */
    /* parameter defaults; per-link arrays override the shared values */
    double m, L, EI;
    const double *m_link, *L_link, *EI_link; /* [N] each, or NULL */
    double g, c, k, D;
    const unsigned char *damped; /* [N + 1] joints with a damper, or NULL */
    const unsigned char *sprung; /* [N + 1] joints with a spring, or NULL */
    int structural;       /* add the parameters zeta, ray_a, ray_b (with
                             the defaults below) and their terms of R */
    double zeta, ray_a, ray_b;
    /* initial state (NULL: zero) */
    const double *theta0, *theta0_dot; /* [N] */
    const double *q0, *q0_dot; /* modal amplitudes, link by link, in the
                                  order of the coordinates */
} eom_chain_spec;

/* Add the chain to m; returns the index of its first coordinate, or a
 * negative status (with eom_model_errmsg). The model keeps what the
 * chain's callbacks need (eom_model_attach). */
EOM_API int eom_chain_add(eom_model *m, const eom_chain_spec *spec);

#ifdef __cplusplus
}
#endif
#endif /* EOM_CHAIN_H */
