/*
 * smithwalk.h: the multiple-scattering BSDF of the Smith microsurface (smithwalk, docs/theory.md
 * §13) for C and C++ renderers. Hand-written; it declares what crates/capi/src/lib.rs defines,
 * and crates/capi/tests/c_furnace.rs compiles and runs a C program against both.
 *
 * Build and link (docs/rendering.md, "C and C++"):
 *     cargo build --release -p smithwalk-capi
 *     cc -Icrates/capi/include app.c target/release/libsmithwalk_capi.a -lpthread -ldl -lm
 *
 * Conventions (docs/rendering.md, "Conventions"):
 *   - Directions are double[3] unit vectors in the surface's local frame (z the macro normal, x
 *     and y the axes of alpha_u and alpha_v), both pointing AWAY from the surface; wo lies below
 *     the horizon for a transmission. A dielectric is lit from inside when wi is below the
 *     horizon; for every other material wi with z <= 0 gives 0 (status SMITHWALK_OK).
 *     A direction whose length differs from 1 by more than 1e-5, or that is not finite, is
 *     refused (SMITHWALK_ERROR_DIRECTION). Directions along the horizon (z == 0) give 0.
 *   - eval returns the cosine-weighted lobe f(wi, wo) |cos theta_o| per RGB channel, like
 *     Mitsuba's eval; sample's weight is f |cos theta_o| / density (1 exactly for a lossless
 *     reflection). Never NaN, infinite or negative.
 *   - Transport: SMITHWALK_RADIANCE when wi points towards the camera (path tracing; a
 *     transmission is multiplied by (n_i / n_o)^2), SMITHWALK_IMPORTANCE when wi points towards
 *     the light. Reflection is the same in both.
 *   - pdf is the density for multiple-importance weights only: it approximates, but is not, the
 *     density of sample's directions. Use sample's weight as it is; never divide eval by pdf
 *     for a sampled direction. MIS weights built on pdf keep an estimator unbiased.
 *
 * Random numbers: each call seeds its own PCG-64 stream, stream(seed, numbers), by mixing the
 * 64-bit seed with the bit patterns of a list of doubles (SplitMix64's finalizer, theory §13.5).
 *   - sample: numbers are the caller's (count of them at `numbers`): the renderer's uniforms
 *     for this bounce (Mitsuba passes 3), or, without any, the lane index as a double (a
 *     single number i), which gives the same stream as the Python package's
 *     smithwalk.bsdf.sample(..., u=None) for lane i. The walk draws as many numbers from the
 *     stream as it needs.
 *   - eval: numbers are the six components of wi and wo (the Python package's eval does the
 *     same), so eval needs no uniforms.
 *   - pdf: deterministic, no random numbers.
 * The same seed and numbers give bit-identical results on every thread and machine, and the
 * same bits as the Python package. Derive the seed from pixel, sample index and bounce.
 *
 * Errors: every call returning int returns SMITHWALK_OK (0) or an error code; on an error the
 * outputs are still written (weights and values 0, wo = (0, 0, 1), order 0, bsdf NULL) and
 * smithwalk_last_error() returns one line naming the field, its value and what is allowed.
 * Nothing unwinds or aborts across this interface: an internal error is caught and reported
 * as SMITHWALK_ERROR_INTERNAL.
 *
 * Threads: a smithwalk_bsdf is immutable; any number of threads may call sample, eval and pdf
 * on the same one at once. smithwalk_last_error is per thread.
 */
#ifndef SMITHWALK_H
#define SMITHWALK_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Status codes. */
#define SMITHWALK_OK 0
/* A parameter out of range or not one of the allowed names (also transport). */
#define SMITHWALK_ERROR_PARAMETER 1
/* A required pointer is NULL. */
#define SMITHWALK_ERROR_NULL 2
/* A direction is not finite or not of unit length. */
#define SMITHWALK_ERROR_DIRECTION 3
/* An internal error was caught (a bug in smithwalk: please report it). */
#define SMITHWALK_ERROR_INTERNAL 4

/* Transport modes (Mitsuba's TransportMode). */
#define SMITHWALK_RADIANCE 0u
#define SMITHWALK_IMPORTANCE 1u

/* orders_from when no "k and above" tail is wanted. */
#define SMITHWALK_ORDERS_NO_TAIL UINT32_MAX

/*
 * The parameters of a BSDF. Start from smithwalk_params_default() and change what you need.
 * Names are NUL-terminated UTF-8 strings, read only during smithwalk_bsdf_new.
 */
typedef struct smithwalk_params {
    /* "ggx", "beckmann" or "student-t". Default "ggx". */
    const char *ndf;
    /* "conductor", "dielectric", "lambertian" or "hammon". Default "conductor". */
    const char *material;
    /* A conductor's Fresnel reflectance: "none" (F = 1, a lossless mirror: Mitsuba's
       material = "none"), "schlick" (from f0) or "exact" (from eta and k). Ignored by the other
       materials. Default "none". */
    const char *fresnel;
    /* Roughness along the tangent x and y axes, finite and > 0; equal for an isotropic
       surface. Default 0.5 and 0.5. */
    double alpha_u;
    double alpha_v;
    /* The Student-T shape gamma (ndf "student-t"), finite and > 1.5: 2 is GGX, larger values
       approach Beckmann. Ignored by the other NDFs. Default NaN (not set: "student-t" refuses it). */
    double gamma;
    /* A conductor's real index per channel (fresnel "exact"), finite and > 0; a dielectric's
       relative index n_inside / n_outside in eta[0], finite and > 0. Default 1. */
    double eta[3];
    /* A conductor's extinction coefficient per channel (fresnel "exact"), finite and >= 0.
       Default 0. */
    double k[3];
    /* Reflectance at normal incidence, in [0, 1] (conductor with fresnel "schlick", Hammon's
       coat). Default 1. */
    double f0[3];
    /* Diffuse albedo, in [0, 1] (Lambertian facets, Hammon's base). Default 1. */
    double albedo[3];
    /* The scattering orders kept (order = number of facet interactions): order k (1 to 64) if
       bit k - 1 of orders_mask is set, and every order >= orders_from (>= 1;
       SMITHWALK_ORDERS_NO_TAIL for none). Not empty. Default: mask 0, from 1 (every order).
       Order 2 alone: mask 1 << 1, from SMITHWALK_ORDERS_NO_TAIL; 3 and above: mask 0, from 3.
       Light escaping at another order gets weight 0 from sample and adds nothing to eval. */
    uint64_t orders_mask;
    uint32_t orders_from;
} smithwalk_params;

/* An opaque BSDF. */
typedef struct smithwalk_bsdf smithwalk_bsdf;

/* Writes the defaults (above) into *out. */
void smithwalk_params_default(smithwalk_params *out);

/* Checks *params and builds a BSDF into *out (NULL on an error). Returns SMITHWALK_OK,
   SMITHWALK_ERROR_PARAMETER or SMITHWALK_ERROR_NULL. Cheap (no allocation beyond the handle):
   a renderer with textured parameters may build one per lookup. */
int smithwalk_bsdf_new(const smithwalk_params *params, smithwalk_bsdf **out);

/* Frees a BSDF; NULL is ignored. */
void smithwalk_bsdf_free(smithwalk_bsdf *bsdf);

/* One random walk from wi: the escape direction wo, the weight per RGB channel
   (E[weight g(wo)] = integral of f(wi, wo) |cos theta_o| g(wo) dwo for every g) and the
   scattering order (0: absorbed or lost; order may be NULL). A photon escaping at an order
   outside the BSDF's orders has weight 0 (wo and order still say where and when).
   Random numbers: stream(seed, numbers[0 .. count)) (numbers may be NULL when count is 0). */
int smithwalk_bsdf_sample(const smithwalk_bsdf *bsdf, const double wi[3], uint32_t transport,
                          uint64_t seed, const double *numbers, size_t count, double wo[3],
                          double weight[3], uint32_t *order);

/* An unbiased estimate of f(wi, wo) |cos theta_o| per RGB channel, over the BSDF's orders:
   order 1 in closed form (conductor, dielectric), higher orders by one walk.
   Random numbers: stream(seed, {wi[0], wi[1], wi[2], wo[0], wo[1], wo[2]}). */
int smithwalk_bsdf_eval(const smithwalk_bsdf *bsdf, const double wi[3], const double wo[3],
                        uint32_t transport, uint64_t seed, double value[3]);

/* The MIS density of wo given wi, per unit solid angle over the whole sphere (integrates to 1),
   positive wherever f is. Deterministic. Returns 0 where eval is 0 by rule, and 0 on an
   error (then smithwalk_last_error says which). */
double smithwalk_bsdf_pdf(const smithwalk_bsdf *bsdf, const double wi[3], const double wo[3]);

/* The message of the last failed call on this thread ("" if none): one line naming the field,
   its value and what is allowed. Valid until the next failing call on this thread. */
const char *smithwalk_last_error(void);

#ifdef __cplusplus
}
#endif

#endif /* SMITHWALK_H */
