#!/usr/bin/env python3
"""Count the public surface of the facade crate `texel`, from rustdoc's JSON.

    python3 scripts/public_api.py [--list FILE]

Builds the JSON of the facade and the crates it re-exports (nightly rustdoc, `--no-deps`, into
target/public-api), then walks the facade's modules from the root: every public item, following
`pub use` re-exports (single names and globs) into the other crates' JSON. It prints, by kind, the
items reached (modules, structs, enums, traits, functions, constants, type aliases; fields and
variants are not counted), both as paths (an item re-exported at two paths counts twice) and as
distinct items, and the public inherent methods and trait items of the types reached. It also
lists the texel types a user meets in the signatures, public fields and variants of what it
reaches but cannot name through the facade (`--unnamed`).
"""
import argparse
import collections
import glob
import json
import os
import subprocess
import sys

CRATES = ["texel", "texel-texture", "texel-raster", "texel-scene", "texel-quality",
          "texel-prepare", "texel-lab", "texel-shade", "texel-io"]


def build(target):
    env = dict(os.environ, CARGO_TARGET_DIR=target,
               RUSTDOCFLAGS="-Z unstable-options --output-format json")
    cmd = ["cargo", "+nightly", "doc", "--no-deps", "--quiet"]
    for c in CRATES:
        cmd += ["-p", c]
    subprocess.run(cmd, env=env, check=True)
    return os.path.join(target, "doc")


def kind_of(item):
    inner = item["inner"]
    return next(iter(inner)) if isinstance(inner, dict) else inner


class Surface:
    def __init__(self, docdir):
        self.crates = {}
        for f in glob.glob(os.path.join(docdir, "*.json")):
            with open(f) as fh:
                d = json.load(fh)
            self.crates[d["index"][str(d["root"])]["name"]] = d
        self.paths = set()
        self.items = set()
        self.kinds = collections.Counter()
        self.distinct = collections.Counter()
        self.methods = 0
        self.listed = []
        # Items whose signatures, fields and variants are read for the types they mention.
        self.mentioning = []

    def resolve(self, d, target_id):
        tid = str(target_id)
        if tid in d["index"]:
            return d, d["index"][tid]
        p = d["paths"].get(tid)
        ext = p and d["external_crates"].get(str(p["crate_id"]))
        other = ext and self.crates.get(ext["name"])
        if not other:
            return None, None
        for iid, q in other["paths"].items():
            if q["crate_id"] == 0 and q["path"] == p["path"] and iid in other["index"]:
                return other, other["index"][iid]
        return None, None

    def module(self, d, item, prefix):
        for cid in item["inner"]["module"]["items"]:
            it = d["index"].get(str(cid))
            if it is None or it.get("visibility") != "public":
                continue
            if kind_of(it) != "use":
                self.visit(d, it, prefix + [it["name"]])
                continue
            use = it["inner"]["use"]
            if use.get("id") is None:
                continue
            d2, target = self.resolve(d, use["id"])
            if target is None:
                continue
            if use["is_glob"]:
                if kind_of(target) == "module":
                    self.module(d2, target, prefix)
            else:
                self.visit(d2, target, prefix + [use["name"]])

    def visit(self, d, it, path):
        k = kind_of(it)
        key = (k, "::".join(path))
        if key in self.paths:
            return
        self.paths.add(key)
        self.kinds[k] += 1
        self.listed.append(key)
        ident = (d["index"][str(d["root"])]["name"], it["id"])
        first = ident not in self.items
        self.items.add(ident)
        if first:
            self.distinct[k] += 1
            self.mentioning.append((d, it, "::".join(path)))
        if k == "module":
            self.module(d, it, path)
        elif k in ("struct", "enum", "union") and first:
            for iid in it["inner"][k].get("impls", []):
                imp = d["index"].get(str(iid))
                body = imp and imp["inner"]["impl"]
                if not body or body.get("trait") or body.get("is_synthetic") or body.get("blanket_impl"):
                    continue
                for mid in body["items"]:
                    m = d["index"].get(str(mid))
                    if m and m.get("visibility") == "public":
                        self.methods += 1
                        self.mentioning.append((d, m, "::".join(path + [m["name"]])))
                        self.listed.append(("method", "::".join(path + [m["name"]])))
        elif k == "trait" and first:
            self.methods += len(it["inner"]["trait"]["items"])


    def members(self, d, it):
        """The public fields and the variants (with their fields) of a struct or enum."""
        k = kind_of(it)
        ids = []
        if k == "struct":
            kind = it["inner"]["struct"]["kind"]
            if isinstance(kind, dict):
                body = kind.get("plain") or {}
                ids = body.get("fields", []) if isinstance(body, dict) else []
                ids += [f for f in kind.get("tuple", []) or [] if f is not None]
        elif k == "enum":
            ids = list(it["inner"]["enum"]["variants"])
        out = []
        for i in ids:
            m = d["index"].get(str(i))
            if m is None:
                continue
            if kind_of(m) == "variant":
                out.append(m)
                vk = m["inner"]["variant"]["kind"]
                if isinstance(vk, dict):
                    fs = (vk.get("struct") or {}).get("fields", []) + [
                        f for f in vk.get("tuple", []) or [] if f is not None]
                    out += [d["index"][str(f)] for f in fs if str(f) in d["index"]]
            elif m.get("visibility") == "public":
                out.append(m)
        return out

    def unnamed(self):
        """Texel types mentioned by what is reached that the facade does not reach: (type, where)."""
        found = {}

        def walk(d, node, where):
            if isinstance(node, dict):
                rp = node.get("resolved_path")
                if isinstance(rp, dict) and rp.get("id") is not None:
                    d2, target = self.resolve(d, rp["id"])
                    if target is not None:
                        ident = (d2["index"][str(d2["root"])]["name"], target["id"])
                        if ident not in self.items:
                            q = d2["paths"].get(str(target["id"]))
                            name = "::".join(q["path"]) if q else f"{ident[0]}::{target.get('name')}"
                            found.setdefault(name, where)
                for v in node.values():
                    walk(d, v, where)
            elif isinstance(node, list):
                for v in node:
                    walk(d, v, where)

        for d, it, where in self.mentioning:
            parts = [it] + self.members(d, it)
            for part in parts:
                walk(d, part["inner"], where)
        return sorted(found.items())


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--list", help="write every path reached, one a line, to this file")
    ap.add_argument("--unnamed", action="store_true",
                    help="list the texel types met in signatures that the facade does not name")
    ap.add_argument("--target", default="target/public-api", help="cargo's target directory")
    args = ap.parse_args()
    s = Surface(build(args.target))
    root = s.crates["texel"]
    s.module(root, root["index"][str(root["root"])], ["texel"])
    print("paths by kind:", dict(sorted(s.kinds.items())))
    print(f"public paths: {sum(s.kinds.values())} ({s.kinds['module']} modules)")
    print(f"distinct items: {sum(s.distinct.values())} ({s.distinct['module']} modules)")
    print(f"public inherent methods and trait items of the types reached: {s.methods}")
    unnamed = s.unnamed()
    print(f"texel types met in signatures, fields and variants but not named: {len(unnamed)}")
    if args.unnamed:
        for name, where in unnamed:
            print(f"  {name}  (in {where})")
    if args.list:
        with open(args.list, "w") as fh:
            fh.write("\n".join(f"{k} {p}" for k, p in sorted(s.listed)) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
