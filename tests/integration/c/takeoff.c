/* A take-off through the FMU's shared library with plain C: no Python, no FMI headers.
 *
 *   gcc -o takeoff takeoff.c -ldl
 *   ./takeoff path/to/tcsim_converter.so file:///path/to/resources
 *
 * Drives the converter (pump torque and turbine speed in) from the steady state at stall through a
 * torque step and a turbine run-up; prints time, pump speed and turbine torque every 0.1 s and exits
 * 0 when every call returned fmi2OK and the outputs are finite and plausible. */
#include <dlfcn.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>

typedef void *Component;
typedef int Status;
typedef void (*Logger)(void *, const char *, Status, const char *, const char *, ...);
typedef struct {
    Logger logger;
    void *(*allocate)(size_t, size_t);
    void (*free)(void *);
    void (*step_finished)(void *, Status);
    void *environment;
} Callbacks;

static void logger(void *env, const char *name, Status status, const char *category, const char *message, ...) {
    va_list args;
    (void)env;
    va_start(args, message);
    fprintf(stderr, "[%s] %s status %d: ", name, category, status);
    vfprintf(stderr, message, args);
    fprintf(stderr, "\n");
    va_end(args);
}

typedef Component (*Instantiate)(const char *, int, const char *, const char *, const Callbacks *, int, int);
typedef Status (*Setup)(Component, int, double, double, int, double);
typedef Status (*Call)(Component);
typedef Status (*SetReals)(Component, const unsigned *, size_t, const double *);
typedef Status (*GetReals)(Component, const unsigned *, size_t, double *);
typedef Status (*Step)(Component, double, double, int);
typedef void (*Free)(Component);

#define LOAD(type, name)                               \
    type name = (type)dlsym(lib, #name);               \
    if (!name) {                                       \
        fprintf(stderr, "missing symbol %s\n", #name); \
        return 2;                                      \
    }

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: %s LIBRARY RESOURCE_URI\n", argv[0]);
        return 2;
    }
    void *lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "%s\n", dlerror());
        return 2;
    }
    LOAD(Instantiate, fmi2Instantiate)
    LOAD(Setup, fmi2SetupExperiment)
    LOAD(Call, fmi2EnterInitializationMode)
    LOAD(Call, fmi2ExitInitializationMode)
    LOAD(SetReals, fmi2SetReal)
    LOAD(GetReals, fmi2GetReal)
    LOAD(Step, fmi2DoStep)
    LOAD(Call, fmi2Terminate)
    LOAD(Free, fmi2FreeInstance)

    Callbacks cb = {logger, NULL, NULL, NULL, NULL};
    Component c = fmi2Instantiate("takeoff", 1, "", argv[2], &cb, 0, 0);
    if (!c) return 1;
    const unsigned inputs[2] = {0, 2};   /* pump_torque_nm, turbine_speed_rad_s */
    const unsigned outputs[2] = {1, 3};  /* pump_speed_rad_s, turbine_torque_nm */
    double u[2] = {40.0, 0.0}, y[2];
    int bad = 0;
    bad |= fmi2SetupExperiment(c, 0, 0.0, 0.0, 1, 5.0);
    bad |= fmi2SetReal(c, inputs, 2, u);
    bad |= fmi2EnterInitializationMode(c);
    bad |= fmi2ExitInitializationMode(c);
    const double h = 0.01;
    for (int i = 0; i < 500 && !bad; i++) {
        double t = i * h;
        u[0] = t < 0.1 ? 40.0 : (t < 0.3 ? 40.0 + (t - 0.1) / 0.2 * 210.0 : 250.0);
        u[1] = 40.0 * t;
        bad |= fmi2SetReal(c, inputs, 2, u);
        bad |= fmi2DoStep(c, t, h, 1);
        bad |= fmi2GetReal(c, outputs, 2, y);
        if (!isfinite(y[0]) || !isfinite(y[1]) || y[0] <= 0.0) bad = 1;
        if ((i + 1) % 10 == 0) printf("%.2f %.4f %.4f\n", t + h, y[0], y[1]);
    }
    bad |= fmi2Terminate(c);
    fmi2FreeInstance(c);
    dlclose(lib);
    return bad ? 1 : 0;
}
