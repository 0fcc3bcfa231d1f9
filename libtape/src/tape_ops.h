/* tape_ops.h - THE op table of libtape.
 *
 * One line per operation: name, operand kind, flags, domain of its smooth
 * part, and its meaning. The enum, the name table, the kind and flag tables,
 * every backend's dispatch and the conformance tests are generated from or
 * loop over this list, so an op added here is covered everywhere it must be.
 *
 * Operand kinds (what a0 and a1 of a tape op hold):
 *   LEAF    no operand slots; a0 is an index (independent, parameter or
 *           constant pool entry), a1 unused
 *   UNARY   a0 = operand slot u
 *   UCONST  a0 = operand slot u, a1 = constant pool index of c
 *   UINT    a0 = operand slot u, a1 = the integer k (two's complement)
 *   BINARY  a0 = slot u, a1 = slot t
 *
 * Flags: COMM commutative (the recorder sorts the operands so hash-consing
 * sees a+b and b+a as one op); LIN linear (all second partials vanish);
 * KINK non-differentiable somewhere in its domain.
 *
 * Domains (where the conformance suite samples; outside, results are NaN or
 * infinite and reported as TP_WARN_NONFINITE, never a crash):
 *   ANY all reals;  UPOS u > 0;  UNZ u != 0;  TNZ t != 0;  UNIT |u| < 1;
 *   TAN |u| < pi/2 (away from the poles);  PAIR (u, t) != (0, 0).
 */
#ifndef TAPE_OPS_H
#define TAPE_OPS_H

/* X(name, kind, flags, domain, meaning) */
#define TP_OP_TABLE(X)                                                    \
    X(INDEP, LEAF, 0, ANY, "independent variable number a0")             \
    X(PARAM, LEAF, 0, ANY, "parameter number a0 (value from workspace)")  \
    X(CONST, LEAF, 0, ANY, "constant pool entry a0")                      \
    X(ADD, BINARY, COMM | LIN, ANY, "u + t")                              \
    X(SUB, BINARY, LIN, ANY, "u - t")                                     \
    X(MUL, BINARY, COMM, ANY, "u * t")                                    \
    X(DIV, BINARY, 0, TNZ, "u / t")                                       \
    X(POW, BINARY, 0, UPOS, "u ^ t = exp(t log u)")                       \
    X(ATAN2, BINARY, 0, PAIR, "atan2(u, t): the angle of the point (t, u)") \
    X(HYPOT, BINARY, COMM, PAIR, "sqrt(u^2 + t^2)")                       \
    X(NEG, UNARY, LIN, ANY, "-u")                                         \
    X(ADDC, UCONST, LIN, ANY, "u + c")                                    \
    X(MULC, UCONST, LIN, ANY, "c * u")                                    \
    X(CSUB, UCONST, LIN, ANY, "c - u")                                    \
    X(CDIV, UCONST, 0, UNZ, "c / u")                                      \
    X(POWC, UCONST, 0, UPOS, "u ^ c, c not an integer")                  \
    X(POWI, UINT, 0, UNZ, "u ^ k, k an integer")                          \
    X(SQR, UNARY, 0, ANY, "u * u")                                        \
    X(SQRT, UNARY, 0, UPOS, "square root of u")                           \
    X(EXP, UNARY, 0, ANY, "e ^ u")                                        \
    X(LOG, UNARY, 0, UPOS, "natural logarithm of u")                      \
    X(SIN, UNARY, 0, ANY, "sine of u")                                    \
    X(COS, UNARY, 0, ANY, "cosine of u")                                  \
    X(TAN, UNARY, 0, TAN, "tangent of u")                                 \
    X(ASIN, UNARY, 0, UNIT, "arc sine of u")                              \
    X(ACOS, UNARY, 0, UNIT, "arc cosine of u")                            \
    X(ATAN, UNARY, 0, ANY, "arc tangent of u")                            \
    X(SINH, UNARY, 0, ANY, "hyperbolic sine of u")                        \
    X(COSH, UNARY, 0, ANY, "hyperbolic cosine of u")                      \
    X(TANH, UNARY, 0, ANY, "hyperbolic tangent of u")                     \
    X(ABS, UNARY, KINK, UNZ, "|u|, derivative sign(u) (0 at u = 0)")

enum tp_opcode {
#define TP_OP_ENUM_(name, kind, flags, dom, text) TP_OP_##name,
    TP_OP_TABLE(TP_OP_ENUM_)
#undef TP_OP_ENUM_
        TP_OP_COUNT
};

/* The dep byte of a tape op: the groups of independents it depends on (low
 * bits) and, for a binary op that depends on some group, which operand (if
 * any) is passive: sweeps never write a derivative row or adjoint of a
 * passive slot. */
#define TP_DEP_GROUPS 0x3fu
#define TP_DEP_UPASSIVE 0x40u
#define TP_DEP_TPASSIVE 0x80u
/* Direction rows are padded to a multiple of this many columns. */
#define TP_LANES 4

enum tp_op_kind { TP_KIND_LEAF, TP_KIND_UNARY, TP_KIND_UCONST, TP_KIND_UINT,
                  TP_KIND_BINARY };

enum tp_op_flag { TP_FLAG_COMM = 1, TP_FLAG_LIN = 2, TP_FLAG_KINK = 4 };

enum tp_op_domain { TP_DOM_ANY, TP_DOM_UPOS, TP_DOM_UNZ, TP_DOM_TNZ,
                    TP_DOM_UNIT, TP_DOM_TAN, TP_DOM_PAIR };

#endif /* TAPE_OPS_H */
