/* status.c - status descriptions and the op table as data, both generated
 * from their X-macro lists (tape.h, tape_ops.h). */
#include "tape_internal.h"

const char *tp_strerror(int status)
{
    switch (status) {
#define TP_STATUS_TEXT_(name, value, text) \
    case value: return text;
        TP_STATUS_LIST(TP_STATUS_TEXT_)
#undef TP_STATUS_TEXT_
    default: return "unknown status";
    }
}

const char *tp_status_name(int status)
{
    switch (status) {
#define TP_STATUS_NAME_(name, value, text) \
    case value: return #name;
        TP_STATUS_LIST(TP_STATUS_NAME_)
#undef TP_STATUS_NAME_
    default: return "TP_UNKNOWN";
    }
}

const tp_opinfo tp__opinfo[TP_OP_COUNT] = {
#define TP_OP_INFO_(name, kind, flags, dom, text)                          \
    {#name, TP_KIND_##kind, (unsigned char)(flags), TP_DOM_##dom, text},
#define COMM TP_FLAG_COMM
#define LIN TP_FLAG_LIN
#define KINK TP_FLAG_KINK
    TP_OP_TABLE(TP_OP_INFO_)
#undef COMM
#undef LIN
#undef KINK
#undef TP_OP_INFO_
};
