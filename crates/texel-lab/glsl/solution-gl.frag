#version 330 core
// texel's solution of the texture-filtering lab, by the OpenGL / Vulkan rules.
//
// The eight modes of `texMode`, reading the texture only through texelFetch (one texel of one
// level) and textureSize (a level's size), so that every filter is written out here:
//   1 nearest, 2 bilinear, 3 bilinear on the nearest mip level, 4 trilinear,
//   5-8 anisotropic with at most 2, 4, 8 and 16 trilinear probes.
//
// The rules (docs/guide/conventions.md in texel): texel (i, j) covers [i, i+1) x [j, j+1), so its
// centre is at (i + 0.5, j + 0.5); nearest reads floor(x); bilinear blends the four texels around
// x - 0.5; the level of detail is log2 of the longer screen derivative in texels of level 0;
// mode 3 takes the nearest level, ceil(lod + 0.5) - 1; the anisotropic probes follow
// EXT_texture_filter_anisotropic: N = ceil(|Pmax| / |Pmin|) clamped, at lod log2(|Pmax| / N),
// placed at ((i + 0.5) / N - 0.5) Pmax.

in vec2 texCoord;           // texel's uv: (0, 0) is the top-left texel of level 0
uniform sampler2D texSlot;  // the texture with all its mip levels (GL_NEAREST, never filtered)
uniform int texMode;        // 1-8
out vec4 fragColor;

// Repeat: bring an index into [0, n). GLSL's % is undefined for a negative operand, so the
// remainder is taken through floor.
int wrap(int i, int n) {
    return i - n * int(floor(float(i) / float(n)));
}

// The size of `level`: level 0's halved `level` times, at least 1. (textureSize(texSlot, level)
// gives the same on a correct driver, but Mesa's llvmpipe answers one size for a whole group of
// pixels when their levels differ, so only level 0's size is asked for.)
ivec2 levelSize(int level) {
    return max(textureSize(texSlot, 0) >> level, ivec2(1));
}

// Texel ij of `level`, wrapped.
vec4 fetch(ivec2 ij, int level) {
    ivec2 n = levelSize(level);
    return texelFetch(texSlot, ivec2(wrap(ij.x, n.x), wrap(ij.y, n.y)), level);
}

// The last level: the pyramid goes down to 1 x 1.
int lastLevel() {
    ivec2 n = textureSize(texSlot, 0);
    return int(floor(log2(float(max(n.x, n.y)))));
}

// Nearest on level 0: the texel whose square holds the point.
vec4 nearest(vec2 p) {
    vec2 x = p * vec2(textureSize(texSlot, 0));
    return fetch(ivec2(floor(x)), 0);
}

// Bilinear on `level`: the four texels whose centres surround the point.
vec4 bilinear(vec2 p, int level) {
    vec2 x = p * vec2(levelSize(level)) - 0.5;
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

// Trilinear at `lod`: the two levels around it, blended by its fraction. lod <= 0 is
// magnification: bilinear on level 0.
vec4 trilinear(vec2 p, float lod) {
    if (lod <= 0.0) {
        return bilinear(p, 0);
    }
    float d = clamp(lod, 0.0, float(lastLevel()));
    float k = floor(d);
    float t = d - k;
    vec4 a = bilinear(p, int(k));
    if (t > 0.0 && int(k) < lastLevel()) {
        return a + (bilinear(p, int(k) + 1) - a) * t;
    }
    return a;
}

void main() {
    vec2 size = vec2(textureSize(texSlot, 0));
    vec2 dx = dFdx(texCoord);
    vec2 dy = dFdy(texCoord);
    // The screen derivatives in texels of level 0.
    float lx = length(dx * size);
    float ly = length(dy * size);
    float lod = log2(max(lx, ly));
    if (texMode == 1) {
        fragColor = nearest(texCoord);
    } else if (texMode == 2) {
        fragColor = bilinear(texCoord, 0);
    } else if (texMode == 3) {
        // The nearest level (Vulkan's rounding), bilinear inside it.
        int level = 0;
        if (lod > 0.0) {
            float d = clamp(lod, 0.0, float(lastLevel()));
            level = max(int(ceil(d + 0.5)) - 1, 0);
        }
        fragColor = bilinear(texCoord, level);
    } else if (texMode == 4) {
        fragColor = trilinear(texCoord, lod);
    } else {
        // Anisotropic: at most 2, 4, 8 or 16 trilinear probes along the longer axis.
        int maxProbes = 1 << (texMode - 4);
        if (lod <= 0.0) {
            fragColor = bilinear(texCoord, 0);
            return;
        }
        float major = max(lx, ly);
        float minor = min(lx, ly);
        vec2 axis = lx >= ly ? dx : dy;
        int n = minor > 0.0 ? int(ceil(major / minor * (1.0 - 1e-5))) : maxProbes;
        n = clamp(n, 1, maxProbes);
        if (n == 1) {
            // Anisotropy 1: one probe, plain trilinear.
            fragColor = trilinear(texCoord, lod);
            return;
        }
        float probeLod = log2(major / float(n));
        vec4 sum = vec4(0.0);
        for (int i = 0; i < n; i++) {
            float t = (float(i) + 0.5) / float(n) - 0.5;
            sum += trilinear(texCoord + t * axis, probeLod);
        }
        fragColor = sum / float(n);
    }
}
