// Benchmark driver for meshoptimizer's cluster-LOD builder (demo/clusterlod.h), so that our own
// cluster DAG builder can be compared with it on the same inputs. Build and run it through
// benches/clusterlod.sh, which extracts meshoptimizer's source into a scratch folder outside the
// repository (it is never committed here) and compiles this file against it.
//
//   clusterlod-driver INPUT.{ply,obj} [--cut E1,E2,...] [--cut-triangles N1,N2,...] [--out-prefix P]
//
// Reads the mesh (binary little-endian PLY, or OBJ), builds the DAG with clodDefaultConfig(128)
// on one thread from positions only, and prints one JSON object on stdout. --cut takes error
// thresholds as fractions of the input's bounding-box diagonal; for each it selects the DAG cut
// at that error and, with --out-prefix, writes the cut as P-<E>.ply (binary little endian).
// --cut-triangles takes triangle counts; for each it selects the finest cut at a threshold with
// at most that many triangles (bisection over the groups' errors) and writes it as P-t<N>.ply.
#include <errno.h>
#include <float.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "meshoptimizer.h"
#define CLUSTERLOD_IMPLEMENTATION
#include "clusterlod.h"

[[noreturn]] static void die(const char* fmt, ...) {
    va_list args;
    va_start(args, fmt);
    fprintf(stderr, "clusterlod-driver: ");
    vfprintf(stderr, fmt, args);
    fputc('\n', stderr);
    va_end(args);
    exit(1);
}

struct Mesh {
    std::vector<float> positions;      // x y z per vertex
    std::vector<unsigned int> indices; // 3 per triangle
};

static std::string readFile(const char* path) {
    std::ifstream f(path, std::ios::binary);
    if (!f) die("%s: cannot open: %s", path, strerror(errno));
    std::ostringstream data;
    data << f.rdbuf();
    if (f.bad()) die("%s: read error", path);
    return data.str();
}

// ---- PLY: binary little endian only; any scalar types, extra properties and elements ----

struct PlyType { int size = 0; char kind = 0; }; // kind: 'i' signed, 'u' unsigned, 'f' floating point
struct PlyProp { std::string name; bool list = false; PlyType count, item; }; // count: lists only
struct PlyElement { std::string name; size_t count = 0; std::vector<PlyProp> props; };

static PlyType plyType(const std::string& s, const char* path) {
    static const struct { const char *a, *b; int size; char kind; } types[] = {
        {"char", "int8", 1, 'i'}, {"uchar", "uint8", 1, 'u'}, {"short", "int16", 2, 'i'}, {"ushort", "uint16", 2, 'u'},
        {"int", "int32", 4, 'i'}, {"uint", "uint32", 4, 'u'}, {"float", "float32", 4, 'f'}, {"double", "float64", 8, 'f'}};
    for (const auto& t : types)
        if (s == t.a || s == t.b) return {t.size, t.kind};
    die("%s: unknown PLY scalar type '%s'", path, s.c_str());
}

template <typename T> static double get(const unsigned char* b) {
    T v;
    memcpy(&v, b, sizeof(T));
    return double(v);
}

// Bounds-checked reader over the binary body; values come back as double, which holds every PLY
// integer type exactly. main() checks that the host is little endian.
struct Cursor {
    const unsigned char *p, *end;
    const char* path;

    double read(PlyType t) {
        if (end - p < t.size) die("%s: file ends inside the PLY body (truncated, or wrong header counts)", path);
        const unsigned char* b = p;
        p += t.size;
        switch (t.size) {
        case 1: return t.kind == 'i' ? get<int8_t>(b) : get<uint8_t>(b);
        case 2: return t.kind == 'i' ? get<int16_t>(b) : get<uint16_t>(b);
        case 4: return t.kind == 'f' ? get<float>(b) : t.kind == 'i' ? get<int32_t>(b) : get<uint32_t>(b);
        default: return get<double>(b);
        }
    }
};

static Mesh readPly(const char* path, const std::string& data) {
    size_t body = data.find("end_header");
    if (body == std::string::npos || (body = data.find('\n', body)) == std::string::npos)
        die("%s: PLY header has no end_header line", path);
    std::istringstream header(data.substr(0, body));
    std::vector<PlyElement> elements;
    bool format_seen = false;
    for (std::string line, word; std::getline(header, line);) {
        std::istringstream ls(line); // ">>" also drops the '\r' of CRLF headers
        if (!(ls >> word) || word == "ply" || word == "comment" || word == "obj_info" || word == "end_header") continue;
        if (word == "format") {
            ls >> word;
            if (word != "binary_little_endian")
                die("%s: PLY format '%s' is not supported, only binary_little_endian (convert the file)", path, word.c_str());
            format_seen = true;
        } else if (word == "element") {
            PlyElement e;
            if (!(ls >> e.name >> e.count) || e.count > data.size()) // a count the file cannot hold
                die("%s: bad PLY header line '%s'", path, line.c_str());
            elements.push_back(e);
        } else if (word == "property" && !elements.empty()) {
            PlyProp p;
            std::string type, item;
            ls >> type;
            if ((p.list = type == "list")) {
                ls >> type >> item;
                p.count = plyType(type, path);
                if (p.count.kind == 'f') die("%s: PLY list with a floating-point count type", path);
                type = item;
            }
            ls >> p.name;
            p.item = plyType(type, path);
            elements.back().props.push_back(p);
        } else
            die("%s: unexpected PLY header line '%s'", path, line.c_str());
    }
    if (!format_seen) die("%s: PLY header has no format line", path);

    Mesh mesh;
    size_t vertex_count = 0;
    bool have_vertices = false, have_faces = false;
    Cursor cur = {(const unsigned char*)data.data() + body + 1, (const unsigned char*)data.data() + data.size(), path};
    // The body holds the elements in header order, so each is read (or skipped) value by value.
    for (const PlyElement& e : elements) {
        bool is_vertex = e.name == "vertex" && !have_vertices;
        bool strips = e.name == "tristrips"; // igea.ply: one strip list where -1 restarts a strip
        bool is_face = (e.name == "face" || strips) && have_vertices;
        int slot[64]; // which of x/y/z each vertex property is, or -1
        if (is_vertex) {
            if (e.props.size() > 64) die("%s: too many vertex properties", path);
            int found = 0;
            for (size_t i = 0; i < e.props.size(); ++i) {
                const std::string& n = e.props[i].name;
                slot[i] = e.props[i].list ? -1 : n == "x" ? 0 : n == "y" ? 1 : n == "z" ? 2 : -1;
                found |= slot[i] >= 0 ? 1 << slot[i] : 0;
            }
            if (found != 7) die("%s: PLY vertex element lacks scalar x, y or z", path);
            vertex_count = e.count;
            mesh.positions.resize(e.count * 3);
        }
        for (size_t i = 0; i < e.count; ++i)
            for (size_t pi = 0; pi < e.props.size(); ++pi) {
                const PlyProp& p = e.props[pi];
                if (!p.list) {
                    double v = cur.read(p.item);
                    if (is_vertex && slot[pi] >= 0) mesh.positions[i * 3 + slot[pi]] = float(v);
                    continue;
                }
                double n = cur.read(p.count);
                if (n < 0) die("%s: %s %zu: negative list length", path, e.name.c_str(), i);
                bool wanted = is_face && (p.name == "vertex_indices" || p.name == "vertex_index");
                if (wanted && !strips && n != 3)
                    die("%s: face %zu has %g corners; only triangles are supported (triangulate first)", path, i, n);
                unsigned int prev[2] = {0, 0};
                for (size_t k = 0, run = 0; k < size_t(n); ++k) {
                    double v = cur.read(p.item);
                    if (!wanted) continue;
                    if (strips && v == -1) { run = 0; continue; }
                    if (v < 0 || v >= double(vertex_count) || v != std::floor(v))
                        die("%s: %s %zu: vertex index %g out of range (%zu vertices)", path, e.name.c_str(), i, v, vertex_count);
                    unsigned int idx = unsigned(v);
                    // Strip triangles alternate their winding; those with a repeated index only join
                    // strips and are dropped: the same decoding as our own PLY reader.
                    if (!strips)
                        mesh.indices.push_back(idx);
                    else if (run >= 2 && prev[0] != prev[1] && prev[1] != idx && prev[0] != idx)
                        mesh.indices.insert(mesh.indices.end(), {prev[run % 2], prev[1 - run % 2], idx});
                    prev[0] = prev[1], prev[1] = idx, run++;
                }
            }
        have_vertices |= is_vertex;
        have_faces |= is_face;
    }
    if (!have_vertices || !have_faces) die("%s: PLY needs a 'vertex' element, then 'face' (or 'tristrips')", path);
    return mesh;
}

// ---- OBJ: "v x y z" and triangular "f" lines; everything else (vt, vn, g, usemtl...) is ignored ----

static Mesh readObj(const char* path, const std::string& data) {
    Mesh mesh;
    std::istringstream in(data);
    size_t line_no = 0;
    for (std::string line; std::getline(in, line);) {
        line_no++;
        const char* s = line.c_str();
        if (s[0] == 'v' && (s[1] == ' ' || s[1] == '\t')) {
            char* end = (char*)s + 1;
            for (int k = 0; k < 3; ++k) {
                const char* start = end;
                mesh.positions.push_back(strtof(start, &end));
                if (end == start) die("%s:%zu: vertex needs three coordinates", path, line_no);
            }
        } else if (s[0] == 'f' && (s[1] == ' ' || s[1] == '\t')) {
            std::istringstream ls(line.substr(2));
            long vertex_count = long(mesh.positions.size() / 3), corners = 0;
            for (std::string corner; ls >> corner; corners++) {
                char* end;
                long v = strtol(corner.c_str(), &end, 10); // "a", "a/b", "a//c", "a/b/c": the position comes first
                if (end == corner.c_str() || (*end && *end != '/')) die("%s:%zu: bad face corner '%s'", path, line_no, corner.c_str());
                long idx = v < 0 ? vertex_count + v : v - 1; // negative indices count back from the last vertex
                if (v == 0 || idx < 0 || idx >= vertex_count)
                    die("%s:%zu: vertex index %ld out of range (%ld vertices so far)", path, line_no, v, vertex_count);
                mesh.indices.push_back(unsigned(idx));
            }
            if (corners != 3)
                die("%s:%zu: face has %ld corners; only triangles are supported (triangulate first)", path, line_no, corners);
        }
    }
    return mesh;
}

// ---- the DAG, collected from clodBuild's callback ----

struct Cluster {
    int group;   // the group this cluster is a member of (the callback call that listed it)
    int refined; // the group whose simplification produced it, or -1 for original geometry
    clodBounds bounds;
    size_t first, count; // its indices in Dag::indices
};

struct Dag {
    std::vector<clodGroup> groups; // depth and simplified bounds, in callback order
    std::vector<Cluster> clusters;
    std::vector<unsigned int> indices; // copies: clusterlod's pointers die with the callback
    double callback_seconds = 0;       // this copying is inside the timed clodBuild call
};

// clodBuild passes each group together with the clusters that are *in* it (the ones it merges and
// simplifies). The id returned here becomes clodCluster::refined of the clusters made from this
// group's simplified geometry, so it has to be the group's index in Dag::groups.
static int onGroup(void* context, clodGroup group, const clodCluster* clusters, size_t cluster_count) {
    auto start = std::chrono::steady_clock::now();
    Dag& dag = *static_cast<Dag*>(context);
    int id = int(dag.groups.size());
    dag.groups.push_back(group);
    for (size_t i = 0; i < cluster_count; ++i) {
        const clodCluster& c = clusters[i];
        dag.clusters.push_back({id, c.refined, c.bounds, dag.indices.size(), c.index_count});
        dag.indices.insert(dag.indices.end(), c.indices, c.indices + c.index_count);
    }
    dag.callback_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return id;
}

// Writes triangles (indices into the original positions) with only the vertices they use.
static void writePly(const std::string& path, const Mesh& mesh, const std::vector<unsigned int>& indices) {
    std::vector<unsigned int> remap(mesh.positions.size() / 3, ~0u);
    std::vector<float> verts;
    std::vector<unsigned char> faces;
    for (size_t i = 0; i < indices.size(); ++i) {
        unsigned int& r = remap[indices[i]];
        if (r == ~0u) {
            r = unsigned(verts.size() / 3);
            verts.insert(verts.end(), &mesh.positions[indices[i] * 3], &mesh.positions[indices[i] * 3] + 3);
        }
        if (i % 3 == 0) faces.push_back(3);
        int32_t v = int32_t(r);
        faces.insert(faces.end(), (unsigned char*)&v, (unsigned char*)&v + 4);
    }
    FILE* f = fopen(path.c_str(), "wb");
    if (!f) die("%s: cannot create: %s", path.c_str(), strerror(errno));
    fprintf(f, "ply\nformat binary_little_endian 1.0\ncomment clusterlod cut\nelement vertex %zu\n"
               "property float x\nproperty float y\nproperty float z\nelement face %zu\n"
               "property list uchar int vertex_indices\nend_header\n", verts.size() / 3, indices.size() / 3);
    fwrite(verts.data(), sizeof(float), verts.size(), f);
    fwrite(faces.data(), 1, faces.size(), f);
    if (ferror(f) || fclose(f) != 0) die("%s: write error", path.c_str());
}

static std::string json(const std::string& s) {
    std::string r = "\"";
    char buf[8];
    for (unsigned char c : s) {
        if (c == '"' || c == '\\') r += '\\';
        if (c < 0x20) snprintf(buf, sizeof(buf), "\\u%04x", c), r += buf;
        else r += char(c);
    }
    return r + "\"";
}

int main(int argc, char** argv) {
    const uint32_t one = 1;
    if (*(const unsigned char*)&one != 1) die("this driver assumes a little-endian host");
    const char* usage = "usage: clusterlod-driver INPUT.{ply,obj} [--cut E1,E2,...] [--cut-triangles N1,N2,...] [--out-prefix P]";
    const char* input = NULL;
    std::string cut_list, prefix, count_list;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        if ((a == "--cut" || a == "--out-prefix") && i + 1 < argc) (a == "--cut" ? cut_list : prefix) = argv[++i];
        else if (a == "--cut-triangles" && i + 1 < argc) count_list = argv[++i];
        else if (a[0] != '-' && !input) input = argv[i];
        else die("%s (bad argument '%s')", usage, a.c_str());
    }
    if (!input) die("%s", usage);
    std::vector<std::string> cut_names; // as typed, for the file names
    std::vector<double> cuts;
    std::istringstream cut_stream(cut_list);
    for (std::string token; std::getline(cut_stream, token, ',');) {
        char* end;
        double e = strtod(token.c_str(), &end);
        if (token.empty() || *end || !(e >= 0)) die("--cut: '%s' is not a non-negative number", token.c_str());
        cut_names.push_back(token);
        cuts.push_back(e);
    }

    std::vector<std::string> count_names;
    std::vector<size_t> counts;
    std::istringstream count_stream(count_list);
    for (std::string token; std::getline(count_stream, token, ',');) {
        char* end;
        unsigned long long n = strtoull(token.c_str(), &end, 10);
        if (token.empty() || *end || token[0] == '-') die("--cut-triangles: '%s' is not a count", token.c_str());
        count_names.push_back(token);
        counts.push_back(size_t(n));
    }

    std::string data = readFile(input);
    Mesh mesh = data.compare(0, 3, "ply") == 0 ? readPly(input, data) : readObj(input, data);
    size_t vertex_count = mesh.positions.size() / 3;
    if (mesh.indices.empty()) die("%s: no triangles", input);

    clodMesh cm = {}; // positions only: no attributes, weights or locks
    cm.indices = mesh.indices.data();
    cm.index_count = mesh.indices.size();
    cm.vertex_count = vertex_count;
    cm.vertex_positions = mesh.positions.data();
    cm.vertex_positions_stride = sizeof(float) * 3;

    Dag dag;
    dag.indices.reserve(mesh.indices.size() * 2); // the DAG holds about twice the input: no regrowth while timed
    auto start = std::chrono::steady_clock::now();
    clodBuild(clodDefaultConfig(128), cm, &dag, onGroup);
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    // A cluster's depth is one more than that of the group that produced it; that is also the depth
    // of the group it is in, which is checked as a test of how the DAG was collected.
    std::vector<size_t> per_level;
    size_t dag_triangles = 0, depth_mismatch = 0;
    int levels = 0;
    for (const clodGroup& g : dag.groups)
        levels = std::max(levels, g.depth + 1);
    for (const Cluster& c : dag.clusters) {
        size_t d = c.refined == -1 ? 0 : size_t(dag.groups[c.refined].depth + 1);
        depth_mismatch += d != size_t(dag.groups[c.group].depth);
        if (per_level.size() <= d) per_level.resize(d + 1);
        per_level[d] += c.count / 3;
        dag_triangles += c.count / 3;
    }
    if (depth_mismatch) fprintf(stderr, "clusterlod-driver: warning: %zu clusters are in a group of another depth\n", depth_mismatch);

    float lo[3] = {FLT_MAX, FLT_MAX, FLT_MAX}, hi[3] = {-FLT_MAX, -FLT_MAX, -FLT_MAX};
    for (size_t i = 0; i < vertex_count * 3; ++i)
        lo[i % 3] = std::min(lo[i % 3], mesh.positions[i]), hi[i % 3] = std::max(hi[i % 3], mesh.positions[i]);
    double diagonal = std::sqrt(double(hi[0] - lo[0]) * (hi[0] - lo[0]) + double(hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                double(hi[2] - lo[2]) * (hi[2] - lo[2]));

    printf("{\"input\": %s, \"input_vertices\": %zu, \"input_triangles\": %zu, \"seconds_build\": %.6f, \"seconds_callback\": %.6f, "
           "\"threads\": 1, \"clusters\": %zu, \"groups\": %zu, \"levels\": %d, \"triangles_per_level\": [",
        json(input).c_str(), vertex_count, mesh.indices.size() / 3, seconds, dag.callback_seconds, dag.clusters.size(),
        dag.groups.size(), levels);
    for (size_t d = 0; d < per_level.size(); ++d)
        printf("%s%zu", d ? ", " : "", per_level[d]);
    const char* commit = getenv("MESHOPT_COMMIT");
    printf("], \"dag_triangles\": %zu, \"diagonal\": %.9g, \"meshoptimizer_commit\": %s, \"group_errors\": [",
        dag_triangles, diagonal, json(commit && *commit ? commit : "unknown").c_str());
    // Per depth, the median and the largest simplified error of its groups (of the diagonal; the
    // terminal groups' FLT_MAX left out): how evenly the error grows up the DAG.
    for (int d = 0; d < levels; ++d) {
        std::vector<float> e;
        for (const clodGroup& g : dag.groups)
            if (g.depth == d && g.simplified.error < FLT_MAX) e.push_back(g.simplified.error);
        std::sort(e.begin(), e.end());
        double median = e.empty() ? 0 : e[e.size() / 2] / diagonal, most = e.empty() ? 0 : e.back() / diagonal;
        printf("%s[%.4g, %.4g]", d ? ", " : "", median, most);
    }
    printf("], \"cuts\": [");

    // The rule from clusterlod.h. groups[refined].simplified.error is the error of the cluster
    // itself (it is part of that group's simplified output; 0 for original geometry), and the
    // simplified error of the group it is in is that of its next coarser version (FLT_MAX when
    // there is none): render the clusters that are fine enough while their coarser version is not.
    auto cut = [&](double t, size_t* clusters) {
        std::vector<unsigned int> tris;
        *clusters = 0;
        for (const Cluster& c : dag.clusters)
            if (dag.groups[c.group].simplified.error > t && (c.refined == -1 || dag.groups[c.refined].simplified.error <= t)) {
                tris.insert(tris.end(), &dag.indices[c.first], &dag.indices[c.first] + c.count);
                ++*clusters;
            }
        return tris;
    };
    for (size_t ci = 0; ci < cuts.size(); ++ci) {
        double t = cuts[ci] * diagonal;
        size_t clusters;
        std::vector<unsigned int> tris = cut(t, &clusters);
        std::string file = prefix.empty() ? "" : prefix + "-" + cut_names[ci] + ".ply";
        if (!file.empty()) writePly(file, mesh, tris);
        printf("%s{\"error\": %.9g, \"threshold\": %.9g, \"triangles\": %zu, \"clusters\": %zu, \"file\": %s}", ci ? ", " : "",
            cuts[ci], t, tris.size() / 3, clusters, file.empty() ? "null" : json(file).c_str());
    }
    printf("], \"triangle_cuts\": [");
    // The cut only changes at a group's error: the smallest of those (or 0) whose cut fits, by
    // bisection (a larger threshold never draws more triangles).
    std::vector<double> at(1, 0.0);
    for (const clodGroup& g : dag.groups)
        if (g.simplified.error < FLT_MAX) at.push_back(g.simplified.error);
    std::sort(at.begin(), at.end());
    at.erase(std::unique(at.begin(), at.end()), at.end());
    for (size_t ci = 0; ci < counts.size(); ++ci) {
        size_t lo = 0, hi = at.size() - 1, clusters;
        while (lo < hi) {
            size_t mid = (lo + hi) / 2;
            if (cut(at[mid], &clusters).size() / 3 <= counts[ci]) hi = mid;
            else lo = mid + 1;
        }
        std::vector<unsigned int> tris = cut(at[lo], &clusters);
        std::string file = prefix.empty() ? "" : prefix + "-t" + count_names[ci] + ".ply";
        if (!file.empty()) writePly(file, mesh, tris);
        printf("%s{\"triangles_max\": %zu, \"error\": %.9g, \"triangles\": %zu, \"clusters\": %zu, \"file\": %s}", ci ? ", " : "",
            counts[ci], at[lo] / diagonal, tris.size() / 3, clusters, file.empty() ? "null" : json(file).c_str());
    }
    printf("]}\n");
    return 0;
}
