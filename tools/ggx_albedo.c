/* ggx_albedo.c - generates src/render/ggx_albedo_table.c: the directional
 * albedo E(mu, alpha) of single-scattering GGX reflection with F = 1 and
 * the height-correlated Smith term, and its cosine-weighted average
 * E_avg(alpha) = 2 int_0^1 E(mu) mu dmu, the tables of Kulla and Conty's
 * multiple-scattering energy compensation (C. Kulla and A. Conty,
 * "Revisiting Physically Based Shading at Imageworks", SIGGRAPH 2017
 * course "Physically Based Shading in Theory and Practice").
 *
 *   cc -O2 -std=c11 -o ggx_albedo tools/ggx_albedo.c -lm
 *   ./ggx_albedo > src/render/ggx_albedo_table.c         (make ggx-albedo-table)
 *   ./ggx_albedo dielectric > src/render/ggx_albedo_dielectric_table.c   (the same target)
 *
 * Method: E(mu) = int f cos dwi with f = D G2 / (4 cos_o cos_i); sampling
 * the visible normals of wo (Heitz 2018, "Sampling the GGX Distribution of
 * Visible Normals", JCGT 7(4)) makes each sample's weight f cos / pdf =
 * G2(wo, wi) / G1(wo) (Heitz 2014, eq. 99 for G2), so E is the mean of
 * that ratio over a stratified 2S x S grid of the VNDF's two random numbers
 * (midpoints, the first warped towards the rim of the projected disk), in
 * double precision, independent of rt's float code. Grid: cell centres
 * mu_i = (i + 1/2) / N (E has a singular limit at mu = 0, where it returns
 * to 1) and alpha_j = j / (N - 1), i, j = 0..N-1, alpha floored at 1e-4
 * for the integration (E(mu, 0) = 1 exactly: a mirror). E_avg by the
 * midpoint rule over 4N values of mu. About 15 s of CPU; the output is
 * deterministic.
 *
 * `dielectric`: the same for a rough dielectric interface (rt's bsdf
 * dielectric: exact Fresnel F(wo.h), reflection F G2 / G1(wo), refraction
 * (1 - F) G2 / G1(wo) through the visible normal, Walter et al. 2007,
 * "Microfacet Models for Refraction through Rough Surfaces"), counting
 * energy (flux: the eta^2 radiance factor left out), so a smooth interface
 * has E = F + (1 - F) = 1. Kulla and Conty tabulate E(mu, alpha, eta) from
 * both sides of the interface; here eta = n_wo / n_wi = 1 / r ("enter",
 * wo on the thinner side) and r ("exit"), r = n_dense / n_thin at
 * 1 / r_k^2 = 1 - (8 / 9) k / (NR - 1), from 1 to 3 (E varies with r
 * mostly through the critical angle's cone, 1 - 1 / r^2 of the cosine
 * weighted hemisphere: nearly linear in 1 / r^2), with E_avg(alpha, eta) = 2 int E mu dmu (the
 * midpoint rule over the table's 32 mu, so E_avg is exactly the mean the
 * runtime lookups integrate to). Third, the multiple-scattering flux that
 * crosses the interface from the thin side under uniform illumination,
 *   M(alpha, r) = min(1 - E_avg(alpha, 1/r), 1 - E_avg(alpha, r)) (1 - F_avg(1/r)),
 * F_avg the hemispherical mean of the exact Fresnel reflectance: the
 * multiply scattered light crosses like diffuse light through a smooth
 * interface, scaled so that the side that loses less sends a share
 * 1 - F_avg of its loss through and the other side less (both shares stay
 * in [0, 1]). The dense side's counterpart M / r^2 follows from
 * reciprocity (docs/shading.md, section 14). S = 64 for these (8192
 * samples an entry, 2 x 16 x 32 x 32 entries): about 15 s of CPU.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#define N 32    /* table side */
#define S 128   /* strata per dimension for each E value */

static double lambda(double x, double y, double z, double a)
{
    double t2 = a * a * (x * x + y * y) / (z * z);
    return 0.5 * (sqrt(1.0 + t2) - 1.0);
}

/* E(mu, alpha) by VNDF sampling: mean of G2 / G1(wo). */
static double albedo(double mu, double a)
{
    if (mu < 1e-4)
        mu = 1e-4;
    if (a < 1e-4)
        a = 1e-4;
    double wx = sqrt(1.0 - mu * mu), wy = 0.0, wz = mu;
    double lo = lambda(wx, wy, wz, a);
    /* stretched view direction (Heitz 2018, listing 1) */
    double vx = a * wx, vy = a * wy, vz = wz;
    double vl = sqrt(vx * vx + vy * vy + vz * vz);
    vx /= vl, vy /= vl, vz /= vl;
    double lensq = vx * vx + vy * vy;
    double t1x = 1, t1y = 0, t1z = 0;
    if (lensq > 0) {
        double il = 1.0 / sqrt(lensq);
        t1x = -vy * il, t1y = vx * il, t1z = 0;
    }
    double t2x = vy * t1z - vz * t1y, t2y = vz * t1x - vx * t1z, t2z = vx * t1y - vy * t1x;
    double sum = 0.0;
    for (int i = 0; i < 2 * S; i++) {
        /* u1 = 1 - (1 - v)^4: strata crowd towards u1 = 1, the disk's rim,
         * where GGX's long tail (the normals that send wi below the
         * horizon) lives; each sample weighs du1/dv = 4 (1 - v)^3 */
        double v = (i + 0.5) / (2 * S), w = 4.0 * pow(1.0 - v, 3.0);
        double u1 = 1.0 - pow(1.0 - v, 4.0);
        for (int j = 0; j < S; j++) {
            double u2 = (j + 0.5) / S;
            double r = sqrt(u1), phi = 2.0 * M_PI * u2;
            double p1 = r * cos(phi), p2 = r * sin(phi);
            double s = 0.5 * (1.0 + vz);
            p2 = (1.0 - s) * sqrt(1.0 - p1 * p1) + s * p2;
            double p3 = sqrt(fmax(0.0, 1.0 - p1 * p1 - p2 * p2));
            double nx = p1 * t1x + p2 * t2x + p3 * vx;
            double ny = p1 * t1y + p2 * t2y + p3 * vy;
            double nz = p1 * t1z + p2 * t2z + p3 * vz;
            /* unstretch */
            double hx = a * nx, hy = a * ny, hz = fmax(1e-12, nz);
            double hl = sqrt(hx * hx + hy * hy + hz * hz);
            hx /= hl, hy /= hl, hz /= hl;
            double d = wx * hx + wy * hy + wz * hz;
            double ix = 2 * d * hx - wx, iy = 2 * d * hy - wy, iz = 2 * d * hz - wz;
            if (iz <= 0)
                continue; /* below the horizon: the energy single scattering loses */
            double li = lambda(ix, iy, iz, a);
            sum += w * (1.0 + lo) / (1.0 + lo + li); /* G2 / G1(wo) */
        }
    }
    return sum / (2.0 * S * S);
}

static int conductor_tables(void)
{
    static double e[N][N];
    double eavg[N];
    for (int j = 0; j < N; j++) {
        double a = (double)j / (N - 1);
        for (int i = 0; i < N; i++)
            e[j][i] = j == 0 ? 1.0 : albedo((i + 0.5) / N, a);
        double s = 0.0;
        enum { M = 4 * N };
        for (int k = 0; k < M; k++) {
            double mu = (k + 0.5) / M;
            s += (j == 0 ? 1.0 : albedo(mu, a)) * 2.0 * mu;
        }
        eavg[j] = s / M;
    }
    printf("/* ggx_albedo_table.c - GENERATED by tools/ggx_albedo.c (make ggx-albedo-table); do not edit.\n"
           " * E(mu, alpha): directional albedo of single-scattering GGX reflection,\n"
           " * F = 1, height-correlated Smith, at mu = (i + 1/2) / %d (columns) and alpha = j / %d\n"
           " * (rows); E_avg(alpha) = 2 int E(mu) mu dmu. Used by rt/render/ggx_albedo.h\n"
           " * for Kulla and Conty's (2017) energy compensation. */\n",
           N, N - 1);
    printf("#include \"ggx_albedo_table.h\"\n\n");
    printf("const float rt_ggx_albedo_table[RT_GGX_ALBEDO_N][RT_GGX_ALBEDO_N] = {\n");
    for (int j = 0; j < N; j++) {
        printf("    {");
        for (int i = 0; i < N; i++)
            printf("%s%.6ff", i ? (i % 8 ? ", " : ",\n     ") : "", e[j][i]);
        printf("},\n");
    }
    printf("};\n\nconst float rt_ggx_albedo_avg_table[RT_GGX_ALBEDO_N] = {\n");
    for (int j = 0; j < N; j++)
        printf("%s%.6ff", j ? (j % 8 ? ", " : ",\n    ") : "    ", eavg[j]);
    printf(",\n};\n");
    return 0;
}

#define NR 16   /* dielectric: rows of r = n_dense / n_thin from 1 to 3, uniform in 1 / r^2 */
#define SD 64   /* dielectric: strata per dimension */

/* Exact unpolarised Fresnel reflectance, eta = n_incident / n_transmitted. */
static double fresnel(double ci, double eta)
{
    double s2 = eta * eta * (1.0 - ci * ci);
    if (s2 >= 1.0)
        return 1.0;
    double ct = sqrt(1.0 - s2);
    double rs = (eta * ci - ct) / (eta * ci + ct), rp = (ci - eta * ct) / (ci + eta * ct);
    return 0.5 * (rs * rs + rp * rp);
}

/* Reflected and transmitted energy of single-scattering rough glass seen
 * at mu from the side where eta = n_wo / n_wi, by VNDF sampling as above. */
static void albedo_dielectric(double mu, double a, double eta, double *refl, double *trans)
{
    if (mu < 1e-4)
        mu = 1e-4;
    if (a < 1e-4)
        a = 1e-4;
    double wx = sqrt(1.0 - mu * mu), wz = mu;
    double lo = lambda(wx, 0.0, wz, a);
    double vx = a * wx, vz = wz;
    double vl = sqrt(vx * vx + vz * vz);
    vx /= vl, vz /= vl;
    /* t1 = (0, 1, 0) for a view in the xz plane, t2 = v x t1 */
    double t2x = -vz, t2z = vx;
    double r_sum = 0.0, t_sum = 0.0;
    static double cphi[SD], sphi[SD];
    for (int j = 0; j < SD; j++)
        cphi[j] = cos(2.0 * M_PI * (j + 0.5) / SD), sphi[j] = sin(2.0 * M_PI * (j + 0.5) / SD);
    for (int i = 0; i < 2 * SD; i++) {
        double v = (i + 0.5) / (2 * SD), w = 4.0 * pow(1.0 - v, 3.0);
        double u1 = 1.0 - pow(1.0 - v, 4.0), r = sqrt(u1);
        for (int j = 0; j < SD; j++) {
            double p1 = r * cphi[j], p2 = r * sphi[j];
            double s = 0.5 * (1.0 + vz);
            p2 = (1.0 - s) * sqrt(1.0 - p1 * p1) + s * p2;
            double p3 = sqrt(fmax(0.0, 1.0 - p1 * p1 - p2 * p2));
            /* n = p1 t1 + p2 t2 + p3 v, t1 = (0, 1, 0) */
            double nx = p2 * t2x + p3 * vx, ny = p1, nz = p2 * t2z + p3 * vz;
            double hx = a * nx, hy = a * ny, hz = fmax(1e-12, nz);
            double hl = sqrt(hx * hx + hy * hy + hz * hz);
            hx /= hl, hy /= hl, hz /= hl;
            double c = wx * hx + wz * hz;
            if (c <= 0)
                continue;
            double f = fresnel(c, eta);
            double ix = 2 * c * hx - wx, iy = 2 * c * hy, iz = 2 * c * hz - wz;
            if (iz > 0)
                r_sum += w * f * (1.0 + lo) / (1.0 + lo + lambda(ix, iy, iz, a));
            double s2 = eta * eta * (1.0 - c * c);
            if (s2 < 1.0) {
                double ct = sqrt(1.0 - s2), k = eta * c - ct;
                double tx = -eta * wx + k * hx, ty = k * hy, tz = -eta * wz + k * hz;
                if (tz < 0)
                    t_sum += w * (1.0 - f) * (1.0 + lo) / (1.0 + lo + lambda(tx, ty, tz, a));
            }
        }
    }
    *refl = r_sum / (2.0 * SD * SD);
    *trans = t_sum / (2.0 * SD * SD);
}

/* F_avg = 2 int F(mu) mu dmu, midpoint rule, in double. */
static double fresnel_avg(double eta)
{
    enum { M = 200000 };
    double s = 0.0;
    for (int k = 0; k < M; k++) {
        double mu = (k + 0.5) / M;
        s += fresnel(mu, eta) * 2.0 * mu;
    }
    return s / M;
}

static void print_row(const double *v, int n, const char *indent)
{
    printf("%s{", indent);
    for (int i = 0; i < n; i++)
        printf("%s%.6ff", i ? (i % 8 ? ", " : ",\n ") : "", v[i]);
    printf("}");
}

static int dielectric_tables(void)
{
    static double e[2][NR][N][N], eavg[2][NR][N], m[NR][N];
    for (int k = 0; k < NR; k++) {
        double r = 1.0 / sqrt(1.0 - (8.0 / 9.0) * k / (NR - 1));
        for (int side = 0; side < 2; side++) {
            double eta = side ? r : 1.0 / r;
            for (int j = 0; j < N; j++) {
                double a = (double)j / (N - 1), s = 0.0;
                for (int i = 0; i < N; i++) {
                    double mu = (i + 0.5) / N, re = 0.0, tr = 0.0;
                    if (j == 0) /* smooth: F + (1 - F) */
                        re = fresnel(mu, eta), tr = 1.0 - re;
                    else
                        albedo_dielectric(mu, a, eta, &re, &tr);
                    e[side][k][j][i] = re + tr;
                    s += (re + tr) * 2.0 * mu / N;
                }
                eavg[side][k][j] = j == 0 ? 1.0 : s;
            }
        }
        double fa = fresnel_avg(1.0 / r);
        for (int j = 0; j < N; j++)
            m[k][j] = j == 0 ? 0.0 : fmin(1.0 - eavg[0][k][j], 1.0 - eavg[1][k][j]) * (1.0 - fa);
    }
    printf("/* ggx_albedo_dielectric_table.c - GENERATED by tools/ggx_albedo.c (make ggx-albedo-table:\n"
           " * ggx_albedo dielectric); do not edit.\n"
           " * E(mu, alpha, eta): energy (reflected + transmitted, flux) of single-scattering rough glass\n"
           " * (exact Fresnel, GGX, height-correlated Smith), [side][r][alpha][mu]: side 0 eta = 1 / r\n"
           " * (wo on the thin side), side 1 eta = r, 1 / r^2 = 1 - (8/9) k / %d, alpha = j / %d, mu = (i + 1/2) / %d;\n"
           " * E_avg(alpha, eta) = 2 int E mu dmu [side][r][alpha]; M(alpha, r) [r][alpha], the\n"
           " * multiple-scattering flux crossing from the thin side under uniform light. Used by\n"
           " * rt/render/ggx_albedo.h for Kulla and Conty's (2017) energy compensation of bsdf dielectric. */\n",
           NR - 1, N - 1, N);
    printf("#include \"ggx_albedo_table.h\"\n\n");
    printf("const float rt_ggx_dielectric_table[2][RT_GGX_DIELECTRIC_NR][RT_GGX_ALBEDO_N][RT_GGX_ALBEDO_N] = {\n");
    for (int side = 0; side < 2; side++) {
        printf("  {\n");
        for (int k = 0; k < NR; k++) {
            printf("    {\n");
            for (int j = 0; j < N; j++) {
                print_row(e[side][k][j], N, "     ");
                printf(",\n");
            }
            printf("    },\n");
        }
        printf("  },\n");
    }
    printf("};\n\nconst float rt_ggx_dielectric_avg_table[2][RT_GGX_DIELECTRIC_NR][RT_GGX_ALBEDO_N] = {\n");
    for (int side = 0; side < 2; side++) {
        printf("  {\n");
        for (int k = 0; k < NR; k++) {
            print_row(eavg[side][k], N, "    ");
            printf(",\n");
        }
        printf("  },\n");
    }
    printf("};\n\nconst float rt_ggx_dielectric_ms_table[RT_GGX_DIELECTRIC_NR][RT_GGX_ALBEDO_N] = {\n");
    for (int k = 0; k < NR; k++) {
        print_row(m[k], N, "    ");
        printf(",\n");
    }
    printf("};\n");
    return 0;
}

int main(int argc, char **argv)
{
    if (argc > 1 && strcmp(argv[1], "dielectric") == 0)
        return dielectric_tables();
    if (argc > 1) {
        fprintf(stderr, "usage: ggx_albedo [dielectric] > TABLE.c\n");
        return 2;
    }
    return conductor_tables();
}
