#version 330 core
// texel's solution of the texture-filtering lab, by the handout's formulas.
//
// The eight modes of `texMode`, reading the texture only through texelFetch (one texel of one
// level) and textureSize (a level's size ||tau||):
//   1 nearest, 2 bilinear, 3 bilinear on the mip level ]N[, 4 trilinear,
//   5-8 anisotropic with lambda_max 2, 4, 8 and 16.
//
// The handout's formulas, with P the texture coordinate and [x], ]x[ floor and ceiling:
//   nearest:   (u, v) = (||tau||.x P.x, ||tau||.y P.y), each rounded to the nearest integer;
//   bilinear:  u0 = [u], u1 = ]u[, du = u - u0 (v alike), then two lerps;
//   the level: M = log2(max(||tau0||)), N = min(M, M + log2(max(||Px||, ||Py||))), Px, Py the
//              screen derivatives of P; mode 3 reads ]N[, trilinear blends [N] and ]N[ by N - [N];
//   anisotropic: lambda = min(||Pmax|| / ||Pmin||, lambda_max), the average of bilinear probes at
//              P + (i / (lambda - 1) - 1/2) Pmax, i = 0 .. lambda - 1, blended between two levels
//              as trilinear is, the level from ||Pmin|| (or ||Pmax|| / lambda_max past the clamp).
// Where the handout is silent: N < 0 (magnification) reads level 0; lambda is rounded up to a
// whole number of probes; lambda = 1 is one probe at P (i / (lambda - 1) would divide by zero).

in vec2 texCoord;           // texel's uv: (0, 0) is the top-left texel of level 0
uniform sampler2D texSlot;  // the texture with all its mip levels (GL_NEAREST, never filtered)
uniform int texMode;        // 1-8
out vec4 fragColor;

// Repeat: bring an index into [0, n). GLSL's % is undefined for a negative operand, so the
// remainder is taken through floor.
int wrap(int i, int n) {
    return i - n * int(floor(float(i) / float(n)));
}

// The size ||tau|| of `level`: level 0's halved `level` times, at least 1. (textureSize(texSlot,
// level) gives the same on a correct driver, but Mesa's llvmpipe answers one size for a whole
// group of pixels when their levels differ, so only level 0's size is asked for.)
ivec2 levelSize(int level) {
    return max(textureSize(texSlot, 0) >> level, ivec2(1));
}

// tau_level(ij), wrapped.
vec4 fetch(ivec2 ij, int level) {
    ivec2 n = levelSize(level);
    return texelFetch(texSlot, ivec2(wrap(ij.x, n.x), wrap(ij.y, n.y)), level);
}

// The last level: the pyramid goes down to 1 x 1.
int lastLevel() {
    ivec2 n = textureSize(texSlot, 0);
    return int(floor(log2(float(max(n.x, n.y)))));
}

// Nearest: ||tau|| P rounded to the nearest integer.
vec4 nearest(vec2 p) {
    vec2 x = p * vec2(textureSize(texSlot, 0));
    return fetch(ivec2(floor(x + 0.5)), 0);
}

// Bilinear on `level`: u0 = [u], u1 = ]u[ (u0 + 1 where u is not an integer; where it is, du = 0
// and u1 does not count), du = u - u0.
vec4 bilinear(vec2 p, int level) {
    vec2 x = p * vec2(levelSize(level));
    vec2 base = floor(x);
    vec2 f = x - base;
    ivec2 i = ivec2(base);
    vec4 t00 = fetch(i, level);
    vec4 t10 = fetch(i + ivec2(1, 0), level);
    vec4 t01 = fetch(i + ivec2(0, 1), level);
    vec4 t11 = fetch(i + ivec2(1, 1), level);
    vec4 top = t00 + (t10 - t00) * f.x;
    vec4 bottom = t01 + (t11 - t01) * f.x;
    return top + (bottom - top) * f.y;
}

// Trilinear at level N: levels [N] and ]N[ blended by N - [N]; N <= 0 reads level 0.
vec4 trilinear(vec2 p, float n) {
    float d = clamp(n, 0.0, float(lastLevel()));
    float lo = floor(d);
    float hi = ceil(d);
    float t = d - lo;
    vec4 a = bilinear(p, int(lo));
    if (hi == lo) {
        return a;
    }
    return a + (bilinear(p, int(hi)) - a) * t;
}

void main() {
    ivec2 size0 = textureSize(texSlot, 0);
    float M = log2(float(max(size0.x, size0.y)));
    vec2 px = dFdx(texCoord);
    vec2 py = dFdy(texCoord);
    float lx = length(px);
    float ly = length(py);
    float N = min(M, M + log2(max(lx, ly)));
    if (texMode == 1) {
        fragColor = nearest(texCoord);
    } else if (texMode == 2) {
        fragColor = bilinear(texCoord, 0);
    } else if (texMode == 3) {
        // The coarser level ]N[, at least 0.
        int level = int(clamp(ceil(N), 0.0, float(lastLevel())));
        fragColor = bilinear(texCoord, level);
    } else if (texMode == 4) {
        fragColor = trilinear(texCoord, N);
    } else {
        float lambdaMax = float(1 << (texMode - 4));
        vec2 pmax = lx >= ly ? px : py;
        float lmax = max(lx, ly);
        float lmin = min(lx, ly);
        float ratio = lmin > 0.0 ? lmax / lmin : lambdaMax + 1.0;
        float lambda = min(ratio, lambdaMax);
        int n = clamp(int(ceil(lambda * (1.0 - 1e-5))), 1, int(lambdaMax));
        // The level: from ||Pmin||, or from ||Pmax|| / lambda_max where the clamp bites.
        float level = ratio > lambdaMax ? M + log2(lmax / lambdaMax) : M + log2(lmin);
        level = min(M, level);
        if (n == 1) {
            // Anisotropy 1: one probe at P.
            fragColor = trilinear(texCoord, level);
            return;
        }
        vec4 sum = vec4(0.0);
        for (int i = 0; i < n; i++) {
            float t = float(i) / float(n - 1) - 0.5;
            sum += trilinear(texCoord + t * pmax, level);
        }
        fragColor = sum / float(n);
    }
}
