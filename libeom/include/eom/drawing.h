/* drawing.h - drawings of a model: shapes placed by the coordinates and
 * the time, recorded like probes onto a tape of their own that nothing
 * replays unless asked (docs/libeom.md, "Drawings"). They are what the
 * animation page of a run shows (eom_run_animation in eom/run.h); a model
 * file declares them with `draw` statements (docs/models.md).
 *
 * A drawing fills a fixed number of values, all lengths in m unless said:
 *
 *   kind               values
 *   EOM_DRAW_POINT     3   the point (x, y, z)
 *   EOM_DRAW_SEGMENT   6   its two ends
 *   EOM_DRAW_POLYLINE  3k  k >= 2 points, joined in order
 *   EOM_DRAW_CIRCLE    7   centre (3), radius (1), the normal of its plane
 *   EOM_DRAW_DISK      7   (3, any length but 0; (0, 0, 1) for a planar
 *                          model); a disk is a filled circle
 *   EOM_DRAW_BOX       15  centre (3), edge lengths along the box's own
 *                          axes (3), its rotation (9, row-major, pure
 *                          numbers: body to fixed frame)
 *   EOM_DRAW_CYLINDER  7   the centres of its two ends (6), radius (1)
 *   EOM_DRAW_SPHERE    4   centre (3), radius (1)
 *   EOM_DRAW_FRAME     13  origin (3), rotation (9, pure), the length of
 *                          its axes (1)
 *
 * A model whose drawings are all points, segments, polylines, circles and
 * disks with every z = 0 is planar: the page draws it in the x-y plane.
 */
#ifndef EOM_DRAWING_H
#define EOM_DRAWING_H

#include "eom/eom.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum eom_draw_kind {
    EOM_DRAW_POINT = 1,
    EOM_DRAW_SEGMENT,
    EOM_DRAW_POLYLINE,
    EOM_DRAW_CIRCLE,
    EOM_DRAW_DISK,
    EOM_DRAW_BOX,
    EOM_DRAW_CYLINDER,
    EOM_DRAW_SPHERE,
    EOM_DRAW_FRAME
} eom_draw_kind;

/* Flags of a drawing. */
#define EOM_DRAW_TRAIL 1 /* a point: the page draws the path it has taken */

/* "point", "segment", ... for an eom_draw_kind; NULL for another value. */
EOM_API const char *eom_draw_kind_name(int kind);

/* Add a drawing: name (copied; unique among the model's drawings, a C
 * identifier or a family member name), kind, count values (the table
 * above; a polyline's a multiple of 3, at least 6), its colour rgb
 * (0xRRGGBB), flags (EOM_DRAW_*), and a vector callback f (user passed
 * back, borrowed) that sets all count values in the role of a probe: of
 * q, qd and the time. Returns the drawing's index, or < 0 (EOM_ERR_ARG for
 * a count that does not fit the kind or a trail on another kind than a
 * point, EOM_ERR_NAME for a name given twice). */
EOM_API int eom_model_add_drawing(eom_model *m, const char *name, int kind,
                                  int count, unsigned rgb, int flags,
                                  eom_vector_fn f, void *user);

/* What one drawing of a system is. The strings belong to the system. */
typedef struct eom_drawing {
    const char *name;
    int kind;       /* eom_draw_kind */
    int count;      /* values */
    int offset;     /* its first value in eom_drawings_at's output */
    unsigned rgb;   /* 0xRRGGBB */
    int flags;      /* EOM_DRAW_* */
} eom_drawing;

/* Number of drawings, and of their values in all. 0 for NULL. */
EOM_API int eom_system_ndrawings(const eom_system *s);
EOM_API int eom_system_ndrawing_values(const eom_system *s);
/* Drawing k into *out: EOM_OK, or EOM_ERR_ARG when k is out of range. */
EOM_API int eom_drawing_get(const eom_system *s, int k, eom_drawing *out);
/* The values of every drawing at the state x (2n values) and the time t,
 * in the order the drawings were added, into out
 * (eom_system_ndrawing_values values). Replays the drawings' tape once;
 * a system without drawings does nothing and returns EOM_OK. */
EOM_API int eom_drawings_at(eom_system *s, double t, const double *x,
                            double *out);

#ifdef __cplusplus
}
#endif
#endif /* EOM_DRAWING_H */
