// smithwalk's driver for NVIDIA facet-forge (issue 38 point 5; docs/validation.md, "Side by side
// with facet-forge"). Our code: it only calls facet-forge's public headers, which are NOT in this
// repository (see README.md beside this file for the commit and how to fetch and build).
//
// Modes (all angles in degrees, polar angle from +z; directions in the x-z plane):
//   sigma              reads lines "ndf gamma alpha theta" (ndf = student-t | student-t-exact-sigma | ggx |
//                      beckmann) from stdin and
//                      prints facet-forge's cross section sigma(w) = A(w), the projected area.
//   vndf NDF G A T N SEED
//                      draws N visible normals for the viewing direction at polar angle T with
//                      facet-forge's sampleD_wi of StudentTNDF(alpha A, gamma G) (NDF student-t)
//                      or of BeckmannNDF(alpha A) (NDF beckmann) and prints the counts of a
//                      16 x 16 grid uniform in cos(theta_m) x phi_m (row-major, cos outer); on
//                      stderr the number of invalid normals (NaN or below the horizon), left
//                      out of the grid, and of normals facing away from the direction.
//   walk NDF G A T N SEED
//                      N paths of a perfect mirror (F = 1) on facet-forge's microsurface, the walk
//                      of its Microsurface::sample (sampleHeight for the next height and facet,
//                      the facet BSDF for the next direction) written out here so that the
//                      scattering order of each exit is known, and without its 11-bounce cap (a
//                      path is cut at 10 000 bounces and counted as lost). Prints R1, R2, R3, R4+
//                      lost, and beyond11 (the energy of paths of more than 11 bounces,
//                      which facet-forge's own Microsurface::sample would drop), each with its
//                      standard error.
#include <bsdfs/NDFs/GGX.h>
#include <bsdfs/NDFs/studentT.h>
#include <bsdfs/mirror.h>

#include <boost/math/distributions/students_t.hpp>

#include <cstdio>
#include <cstring>
#include <memory>

// facet-forge's Student-T with its fitted cross section replaced by the exact one, so that a walk
// with it differs from facet-forge's only through the sampler (smithwalk's docs/theory.md §1.6):
// A(w) = max(w_z, 0) + t E[(X - |a|)_+], with t = alpha sin(theta), a = w_z / t, and
// X = T / sqrt(2) the roughness-1 slope marginal, T ~ Student-t with nu = 2 gamma - 2 degrees of
// freedom, whose tail mean is E[(T - b)_+] = (nu + b^2) / (nu - 1) f_nu(b) - b S_nu(b) (f the
// density, S the survival function, both from Boost.Math). Isotropic roughness only.
class ExactSigmaStudentT : public StudentTNDF
{
public:
    ExactSigmaStudentT(const BSDF *bsdf, double alpha, double gamma) : StudentTNDF(bsdf, alpha, alpha, gamma) {}

    virtual double sigma(const Vector3 &wi) const
    {
        const double t = m_roughness_x * sqrt(wi.x * wi.x + wi.y * wi.y);
        if (t == 0.0)
            return std::max(wi.z, 0.0);
        const double nu = 2.0 * m_gamma - 2.0;
        const double b = sqrt(2.0) * std::abs(wi.z) / t;
        const boost::math::students_t law(nu);
        const double tail = (nu + b * b) / (nu - 1.0) * boost::math::pdf(law, b) -
                            b * boost::math::cdf(boost::math::complement(law, b));
        return std::max(wi.z, 0.0) + t * std::max(tail, 0.0) / sqrt(2.0);
    }
};

static Vector3 direction(double theta_deg)
{
    const double t = theta_deg * M_PI / 180.0;
    return Vector3(sin(t), 0.0, cos(t));
}

static std::unique_ptr<ShapeInvariantNDF> make_ndf(const BSDF *facet, const char *ndf, double gamma, double alpha)
{
    if (!strcmp(ndf, "ggx"))
        return std::unique_ptr<ShapeInvariantNDF>(new GGXNDF(facet, alpha, alpha));
    if (!strcmp(ndf, "beckmann"))
        return std::unique_ptr<ShapeInvariantNDF>(new BeckmannNDF(facet, alpha, alpha));
    if (!strcmp(ndf, "student-t"))
        return std::unique_ptr<ShapeInvariantNDF>(new StudentTNDF(facet, alpha, alpha, gamma));
    if (!strcmp(ndf, "student-t-exact-sigma"))
        return std::unique_ptr<ShapeInvariantNDF>(new ExactSigmaStudentT(facet, alpha, gamma));
    fprintf(stderr, "unknown ndf '%s' (allowed: student-t, student-t-exact-sigma, ggx, beckmann)\n", ndf);
    exit(2);
}

static void seed_all(unsigned long seed)
{
    srand48(seed);  // facet-forge's RandomReal
    g_mt.seed(seed); // facet-forge's RandomGamma
}

static int mode_sigma()
{
    char ndf[32];
    double gamma, alpha, theta;
    while (scanf("%31s %lf %lf %lf", ndf, &gamma, &alpha, &theta) == 4)
        printf("%.17g\n", make_ndf(nullptr, ndf, gamma, alpha)->sigma(direction(theta)));
    return 0;
}

static int mode_vndf(const char *name, double gamma, double alpha, double theta, long n, unsigned long seed)
{
    seed_all(seed);
    std::unique_ptr<ShapeInvariantNDF> ndf = make_ndf(nullptr, name, gamma, alpha);
    const Vector3 w = direction(theta);
    std::vector<long> counts(16 * 16, 0);
    long bad = 0, away = 0;
    for (long i = 0; i < n; i++)
    {
        const Vector3 m = ndf->sampleD_wi(w);
        if (!(m.z >= 0.0) || !IsFiniteNumber(m.x))
        {
            bad++;
            continue;
        }
        if (dot(w, m) < 0.0) // a normal the visible-normal density never draws
            away++;
        const int ic = std::min(15, int(m.z * 16));
        double phi = atan2(m.y, m.x);
        if (phi < 0)
            phi += 2 * M_PI;
        const int ip = std::min(15, int(phi / (2 * M_PI) * 16));
        counts[ic * 16 + ip]++;
    }
    for (long c : counts)
        printf("%ld\n", c);
    fprintf(stderr, "invalid %ld facing-away %ld\n", bad, away);
    return 0;
}

static int mode_walk(const char *name, double gamma, double alpha, double theta, long n, unsigned long seed)
{
    seed_all(seed);
    MirrorBRDF mirror;
    std::unique_ptr<ShapeInvariantNDF> ndf = make_ndf(&mirror, name, gamma, alpha);
    const Vector3 wi = direction(theta);
    double r[6] = {0, 0, 0, 0, 0, 0}; // R1, R2, R3, R4+, lost, beyond 11
    for (long i = 0; i < n; i++)
    {
        Vector3 wr = -wi;
        double hr = 0.0;
        double weight = 1.0;
        int order = 0;
        for (;;)
        {
            Vector3 wm;
            const BSDF *facet = nullptr;
            hr = ndf->sampleHeight(wr, hr, true, wm, facet);
            if (hr >= 0.0)
                break;
            if (++order > 10000 || hr != hr)
            {
                order = -1;
                break;
            }
            wr = facet->sample(1.0, 1.0, -wr, weight, wm);
            if (wr.z != wr.z)
            {
                order = -1;
                break;
            }
        }
        if (order < 0)
            r[4] += 1;
        else if (order >= 1)
        {
            r[std::min(order, 4) - 1] += weight;
            if (order > 11) // Microsurface::sample returns weight 0 for these
                r[5] += weight;
        }
        else
            r[4] += 1; // no collision: cannot happen for a direction above the horizon
    }
    const char *names[6] = {"R1", "R2", "R3", "R4+", "lost", "beyond11"};
    for (int k = 0; k < 6; k++)
    {
        // weights are 0 or 1 (F = 1), so the standard error is the binomial one
        const double p = r[k] / n;
        printf("%s %.8f %.8f\n", names[k], p, sqrt(p * (1 - p) / n));
    }
    return 0;
}

int main(int argc, char **argv)
{
    if (argc >= 2 && !strcmp(argv[1], "sigma"))
        return mode_sigma();
    if (argc == 8 && !strcmp(argv[1], "vndf"))
        return mode_vndf(argv[2], atof(argv[3]), atof(argv[4]), atof(argv[5]), atol(argv[6]), strtoul(argv[7], 0, 10));
    if (argc == 8 && !strcmp(argv[1], "walk"))
        return mode_walk(argv[2], atof(argv[3]), atof(argv[4]), atof(argv[5]), atol(argv[6]), strtoul(argv[7], 0, 10));
    fprintf(stderr, "usage: ff_driver sigma < lines 'ndf gamma alpha theta_deg'\n"
                    "       ff_driver vndf NDF GAMMA ALPHA THETA_DEG N SEED\n"
                    "       ff_driver walk NDF GAMMA ALPHA THETA_DEG N SEED   (NDF: student-t | student-t-exact-sigma | ggx | beckmann)\n");
    return 2;
}
