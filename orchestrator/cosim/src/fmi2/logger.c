/* The FMI 2.0 logger callback. fmi2CallbackLogger is variadic (printf-style message and
 * arguments), which stable Rust cannot define, so this formats the message and hands the
 * text to the Rust sink whose address the instance passed as componentEnvironment. */
#include <stdarg.h>
#include <stdio.h>

/* Must match agrisim_cosim::fmi2::log::Env (repr(C)). */
typedef struct {
    void (*sink)(void *ctx, int status, const char *category, const char *message);
    void *ctx;
} agrisim_fmi2_env;

void agrisim_cosim_fmi2_logger(void *env, const char *instance_name, int status, const char *category,
                               const char *message, ...) {
    (void)instance_name;
    agrisim_fmi2_env *e = (agrisim_fmi2_env *)env;
    if (e == NULL || e->sink == NULL) {
        return;
    }
    char text[4096];
    if (message == NULL) {
        text[0] = '\0';
    } else {
        va_list ap;
        va_start(ap, message);
        vsnprintf(text, sizeof text, message, ap);
        va_end(ap);
    }
    e->sink(e->ctx, status, category, text);
}
