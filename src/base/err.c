/* pdt — error records (see common.h). */
#include "pdt/common.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

pdt_status pdt_err_set(pdt_err *err, pdt_status code, const char *fmt, ...)
{
    if (!err || err->code != PDT_OK) return code;
    err->code = code;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->msg, sizeof err->msg, fmt, ap);
    va_end(ap);
    return code;
}

void pdt_err_clear(pdt_err *err)
{
    if (!err) return;
    err->code = PDT_OK;
    err->msg[0] = '\0';
}

const char *pdt_status_str(pdt_status s)
{
    switch (s) {
    case PDT_OK: return "ok";
    case PDT_ERR_NOMEM: return "out of memory";
    case PDT_ERR_IO: return "input/output error";
    case PDT_ERR_PARSE: return "parse error";
    case PDT_ERR_ARG: return "bad argument";
    case PDT_ERR_FORMAT: return "wrong format";
    case PDT_ERR_CORRUPT: return "damaged data";
    case PDT_ERR_MPI: return "communication error";
    case PDT_ERR_CHECK: return "check failed";
    }
    return "unknown error";
}
