#!/usr/bin/python3
"""Writes the fuzz seed corpus (tests/fuzz/corpus/<target>/) from the real scans in tests/data, trimmed to a few
dozen points, plus hand-made edge cases; the LAS, PTX and E57 seeds come from the project's own writers
(write_scan_seeds.cpp, built in the fuzz build). Inputs that were once findings stay next to them as regress_*.
Deterministic; rerun after changing a format and commit the output."""
import math
import os
import struct
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "..", "data")
CORPUS = os.path.join(HERE, "corpus")
POINTS = 40  # per trimmed seed: enough for every record shape, small enough for fast executions


def read(*parts):
    with open(os.path.join(DATA, *parts), "rb") as f:
        return f.read()


def split_header(data, end_marker):
    end = data.index(end_marker) + len(end_marker)
    return data[:end], data[end:]


def trimmed_ply(data, keep=POINTS):
    """A PLY with only its first `keep` vertices (vertex-only files, as the shipped ones)."""
    header, body = split_header(data, b"end_header\n")
    lines = header.split(b"\n")
    count = 0
    for i, line in enumerate(lines):
        if line.startswith(b"element vertex"):
            count = int(line.split()[2])
            lines[i] = b"element vertex %d" % keep
    header = b"\n".join(lines)
    if b"format ascii" in header:
        return header + b"\n".join(body.split(b"\n")[:keep]) + b"\n"
    stride = len(body) // count
    return header + body[: keep * stride]


def trimmed_pcd(data, keep=POINTS):
    end = data.index(b"\n", data.index(b"DATA ")) + 1
    header, body = data[:end], data[end:]
    fields = {}
    for line in header.split(b"\n"):
        parts = line.split()
        if parts and not parts[0].startswith(b"#"):
            fields[parts[0]] = parts[1:]
    count = int(fields[b"POINTS"][0])
    out = []
    for line in header.split(b"\n"):
        if line.startswith(b"WIDTH") or line.startswith(b"POINTS"):
            line = line.split()[0] + b" %d" % keep
        elif line.startswith(b"HEIGHT"):
            line = b"HEIGHT 1"
        out.append(line)
    header = b"\n".join(out)
    if fields[b"DATA"][0] == b"ascii":
        return header + b"\n".join(body.split(b"\n")[:keep]) + b"\n"
    stride = sum(int(s) * int(c) for s, c in zip(fields[b"SIZE"], fields.get(b"COUNT", [b"1"] * len(fields[b"SIZE"]))))
    assert stride * count <= len(body), "binary body shorter than its header says"
    return header + body[: keep * stride]


def lzf_literals(raw):
    """LZF stream made of literal runs only (control byte n-1 then n bytes, n <= 32): valid input for any LZF
    decoder, so the compressed PCD reader sees a well-formed stream."""
    out = bytearray()
    for i in range(0, len(raw), 32):
        run = raw[i : i + 32]
        out.append(len(run) - 1)
        out += run
    return bytes(out)


def pcd_compressed_from_binary(pcd):
    """binary_compressed version of a binary PCD with float fields of SIZE 4 (column-wise, then LZF)."""
    end = pcd.index(b"DATA binary\n")
    header, body = pcd[:end], pcd[end + len(b"DATA binary\n") :]
    sizes = [int(s) for s in next(l for l in header.split(b"\n") if l.startswith(b"SIZE")).split()[1:]]
    n = len(body) // sum(sizes)
    columns = bytearray()
    offset = 0
    for size in sizes:
        for i in range(n):
            start = i * sum(sizes) + offset
            columns += body[start : start + size]
        offset += size
    packed = lzf_literals(bytes(columns))
    return header + b"DATA binary_compressed\n" + struct.pack("<II", len(packed), len(columns)) + packed


def ply_header(fmt, count, props, extra=b""):
    text = b"ply\nformat %s 1.0\n" % fmt + extra + b"element vertex %d\n" % count
    for t, name in props:
        text += b"property %s %s\n" % (t, name)
    return text + b"end_header\n"


def sphere(n=POINTS):
    pts = []
    golden = math.pi * (3 - math.sqrt(5))
    for i in range(n):
        y = 1 - 2 * (i + 0.5) / n
        r = math.sqrt(1 - y * y)
        pts.append((r * math.cos(golden * i), y, r * math.sin(golden * i), float(i % 7)))
    return pts


def ply_seeds():
    seeds = {
        "bunny_binary.ply": trimmed_ply(read("bunny", "bun000.ply")),
        "bunny_ascii.ply": trimmed_ply(read("bunny", "ascii", "bun000.ply")),
    }
    pts = sphere()
    props = [(b"double", b"x"), (b"double", b"y"), (b"double", b"z"), (b"float", b"intensity")]
    big = ply_header(b"binary_big_endian", len(pts), props)
    for x, y, z, i in pts:
        big += struct.pack(">dddf", x + 5240000.0, y + 400000.0, z, i)
    seeds["survey_double_be.ply"] = big
    # A face element with lists before the vertices, ASCII and binary.
    faces = b"element face 2\nproperty list uchar int vertex_indices\n"
    text = b"ply\nformat ascii 1.0\ncomment lists first\n" + faces + b"element vertex 4\nproperty float x\n" \
           b"property float y\nproperty float z\nproperty uchar scalar_Intensity\nend_header\n" \
           b"3 0 1 2\n3 1 2 3\n0 0 0 1\n1 0 0 2\n0 1 0 3\n0 0 1 4\n"
    seeds["faces_first_ascii.ply"] = text
    binary = b"ply\nformat binary_little_endian 1.0\n" + faces + b"element vertex 4\nproperty short x\n" \
             b"property short y\nproperty short z\nend_header\n"
    binary += struct.pack("<B3i", 3, 0, 1, 2) + struct.pack("<B3i", 3, 1, 2, 3)
    binary += b"".join(struct.pack("<3h", *v) for v in [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)])
    seeds["faces_first_binary.ply"] = binary
    # Edge cases: hostile counts, truncation, NaN.
    xyz = [(b"float", b"x"), (b"float", b"y"), (b"float", b"z")]
    seeds["huge_count.ply"] = ply_header(b"binary_little_endian", 10**12, xyz) + b"\0" * 12
    seeds["huge_list.ply"] = b"ply\nformat binary_little_endian 1.0\nelement face 1\nproperty list uint float v\n" \
                             b"element vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n" \
                             + struct.pack("<I", 0xFFFFFFFF)
    seeds["nan.ply"] = ply_header(b"ascii", 2, xyz) + b"1 2 3\nnan inf -inf\n"
    seeds["magic_only.ply"] = b"ply\n"
    return seeds


def pcd_seeds():
    office = trimmed_pcd(read("eth-office", "office1_keypoints.pcd"))
    velodyne = trimmed_pcd(read("velodyne", "251370668.pcd"))
    seeds = {"office_binary.pcd": office, "velodyne_binary.pcd": velodyne,
             "velodyne_compressed.pcd": pcd_compressed_from_binary(velodyne)}
    text = b"# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgb normal\nSIZE 4 4 4 4 4\nTYPE F F F U F\nCOUNT 1 1 1 1 3\n" \
           b"WIDTH 2\nHEIGHT 2\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 4\nDATA ascii\n"
    for i, (x, y, z, _) in enumerate(sphere(4)):
        text += b"%r %r %r %d 0 0 1\n" % (x, y, z, i)
    seeds["organised_ascii.pcd"] = text.replace(b"0 0 1\n", b"nan nan nan\n", 1)
    seeds["huge_count.pcd"] = b"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1000000000000\nHEIGHT 1\n" \
                              b"POINTS 1000000000000\nDATA binary\n" + b"\0" * 12
    seeds["huge_lzf.pcd"] = b"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 357913941\nHEIGHT 1\n" \
                            b"DATA binary_compressed\n" + struct.pack("<II", 8, 357913941 * 12) + b"\xe0\xff" * 4
    return seeds


def text_seeds():
    pts = sphere()
    seeds = {
        "plain.xyz": b"".join(b"%r %r %r\n" % p[:3] for p in pts),
        "count.pts": b"%d\n" % len(pts) + b"".join(b"%r %r %r %d\n" % (p[0], p[1], p[2], p[3]) for p in pts),
        "header.csv": b"x,y,z,intensity\n" + b"".join(b"%r,%r,%r,%r\n" % p for p in pts),
        "survey.txt": b"# survey\r\n" + b"".join(b"%.4f\t%.4f\t%.4f\r\n" % (p[0] + 5240000, p[1] + 400000, p[2]) for p in pts),
        "bom_nan.xyz": b"\xef\xbb\xbf1 2 3\n4 5 NaN\n",
        "huge_count.pts": b"1000000000000\n1 2 3 4\n",
    }
    return seeds


def request_seeds(ply, text):
    """k4reg.v1 messages (protoc --python_out into a temporary folder): path and inline requests, every parameter
    set, out-of-range and non-finite parameters, unknown enum values, a stream header and a chunk. Returns the
    binary seeds (gRPC) and the RegisterRequests as JSON with proto field names (HTTP)."""
    proto_dir = os.path.join(HERE, "..", "..", "proto")
    with tempfile.TemporaryDirectory() as out:
        subprocess.run(["protoc", "-I", proto_dir, "--python_out=" + out,
                        os.path.join(proto_dir, "k4reg", "v1", "registration.proto")], check=True)
        sys.path.insert(0, out)
        from k4reg.v1 import registration_pb2 as pb
        from google.protobuf import json_format

    json_seeds = {}

    def request(source, target, **params):
        r = pb.RegisterRequest(params=pb.RegistrationParams(**params))
        for cloud, value in ((r.source, source), (r.target, target)):
            if isinstance(value, str):
                cloud.path = value
            else:
                cloud.inline_cloud.file_name, cloud.inline_cloud.data = value
        json_seeds["%02d.json" % len(json_seeds)] = json_format.MessageToJson(
            r, preserving_proto_field_name=True).encode()
        return r.SerializeToString()

    every = dict(min_scale_m=0.004, overlap=0.9, octaves=3, scales_per_octave=4, min_contrast=0.02, signal=3,
                 method=2, plain_voxel_m=0.01, max_bases=100, hypotheses_kept=3, icp=False, icp_max_iterations=10,
                 seed=7, threads=1, time_budget_s=5.0, free_space=3)
    seeds = {
        "paths.bin": request("bun045.ply", "bun000.ply", min_scale_m=0.001, overlap=0.9),
        "inline_every_param.bin": request(("a.xyz", text["plain.xyz"]), ("b.ply", ply["bunny_binary.ply"]), **every),
        "inline_no_names.bin": request(("", ply["faces_first_binary.ply"]), ("", text["count.pts"])),
        "nan_scale.bin": request("a.ply", "b.ply", min_scale_m=float("nan")),
        "huge_budget.bin": request("a.ply", "b.ply", time_budget_s=1e300),
        "inf_overlap.bin": request("a.ply", "b.ply", overlap=float("inf")),
        "negative_threads.bin": request("../../etc/passwd", "/", threads=-1, octaves=-5),
        "unknown_enums.bin": request("a.ply", "b.ply", signal=99, method=-1, free_space=1 << 30),
    }
    header = pb.RegisterStreamRequest()
    header.header.source.upload.file_name = "a.ply"
    header.header.source.upload.size_bytes = 1 << 40
    header.header.source.upload.crc32c = 0xDEADBEEF
    header.header.target.path = "b.ply"
    header.header.params.CopyFrom(pb.RegistrationParams(**every))
    seeds["stream_header.bin"] = header.SerializeToString()
    chunk = pb.RegisterStreamRequest()
    chunk.chunk.role = 1
    chunk.chunk.data = text["plain.xyz"]
    seeds["stream_chunk.bin"] = chunk.SerializeToString()
    # JSON the mapping allows besides what the printer writes: camelCase names, numbers as strings, enum numbers.
    json_seeds["variants.json"] = (b'{"source": {"path": "a.ply"}, "target": {"inlineCloud": {"data": "AAEC", '
                                   b'"fileName": "b.xyz"}}, "params": {"minScaleM": "0.01", "seed": "18446744073709551615",'
                                   b' "signal": 2, "method": "COARSE_METHOD_PLAIN_4PCS", "icp": true, "threads": 1e0}}')
    json_seeds["unknown_field.json"] = b'{"params": {"min_scale": 0.01}}'
    return seeds, json_seeds


def health_request_seeds():
    """Heads as probes, curl and odd clients send them to the health listener (fuzz_health_request)."""
    return {
        "kube_probe.txt": b"GET /healthz HTTP/1.1\r\nHost: 10.0.0.7:8081\r\nUser-Agent: kube-probe/1.29\r\n"
                          b"Accept: */*\r\nConnection: close\r\n\r\n",
        "readyz_query.txt": b"GET /readyz?verbose=1 HTTP/1.1\r\nHost: localhost\r\nx-request-id: probe-1\r\n\r\n",
        "head_http10.txt": b"HEAD /healthz HTTP/1.0\r\n\r\n",
        "empty_values.txt": b"GET /healthz HTTP/1.1\r\nX-Empty:\r\nX-Blank: \t \r\n\r\n",
        "bare_lf.txt": b"GET /healthz HTTP/1.1\nHost: x\n\n",
        "post_body.txt": b"POST /healthz HTTP/1.1\r\nContent-Length: 4\r\n\r\nbody",
        "odd_method.txt": b"FOO /healthz HTTP/1.1\r\n\r\n",
        "http2_preface.txt": b"PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n",
        "unfinished.txt": b"GET /healthz HTTP/1.1\r\nHost: x\r\n",
        "folded.txt": b"GET /healthz HTTP/1.1\r\nX-A: 1\r\n  continued\r\n\r\n",
    }


def http_header_seeds():
    """Header fields, a blank line, then a JSON body: http_request_fuzzer.cpp splits its input there."""
    heads = {
        "same_origin": b"Host: 127.0.0.1:8080\r\nOrigin: http://127.0.0.1:8080\r\nAuthorization: Bearer token\r\n"
                       b"Content-Type: application/json\r\nContent-Length: 2\r\nx-request-id: fuzz-1\r\n",
        "odd": b"Host: a\r\nOrigin: null\r\nX-Empty:\r\nTransfer-Encoding: chunked\r\n"
               b"Content-Length: 99999999999999999999\r\nContent-Type: multipart/form-data; boundary=\r\n",
    }
    return {"headers_%s.http" % name: head + b"\r\n" + b'{"source": {"path": "a.ply"}}' for name, head in heads.items()}


def write(target, seeds):
    folder = os.path.join(CORPUS, target)  # inputs that once were findings (regress_*) stay
    os.makedirs(folder, exist_ok=True)
    for name, data in sorted(seeds.items()):
        with open(os.path.join(folder, name), "wb") as f:
            f.write(data)


def folder_seeds(target):
    folder = os.path.join(CORPUS, target)
    seeds = {}
    for name in sorted(os.listdir(folder)):
        with open(os.path.join(folder, name), "rb") as f:
            seeds[name] = f.read()
    return seeds


def main():
    if len(sys.argv) != 2:
        print("usage: make_corpus.py <fuzz build>/bin/write_scan_seeds  (scripts/fuzz.sh builds it)", file=sys.stderr)
        return 2
    subprocess.run([sys.argv[1], CORPUS], check=True)  # LAS, PTX and E57 seeds from the project's writers
    # fuzz_read_e57 inputs start with a byte, odd = the harness rewrites the page CRCs (e57_fuzzer.cpp): each written
    # file becomes one seed of each kind.
    e57_folder = os.path.join(CORPUS, "fuzz_read_e57")
    e57 = {name: data for name, data in folder_seeds("fuzz_read_e57").items() if name.endswith(".e57") and name[1] != "_"}
    for name in e57:
        os.remove(os.path.join(e57_folder, name))
    write("fuzz_read_e57", {"%d_%s" % (crc, name): bytes([crc]) + data for name, data in e57.items() for crc in (0, 1)})
    ply, pcd, text = ply_seeds(), pcd_seeds(), text_seeds()
    write("fuzz_read_ply", ply)
    write("fuzz_read_pcd", pcd)
    write("fuzz_read_xyz", text)
    # read_cloud_bytes: the first byte picks the file name hint (kNames in cloud_bytes_fuzzer.cpp): 0 .ply,
    # 1 .pcd, 2 .xyz, 3 .txt, 7 .las, 9 .ptx, 10 .e57, 11 no extension.
    mixed = {}
    hints = ((0, "fuzz_read_ply"), (1, "fuzz_read_pcd"), (2, "fuzz_read_xyz"), (11, "fuzz_read_xyz"),
             (7, "fuzz_read_las"), (9, "fuzz_read_ptx"), (3, "fuzz_read_ptx"), (10, "fuzz_read_e57"),
             (11, "fuzz_read_e57"))
    for hint, target in hints:
        for name, data in (e57 if target == "fuzz_read_e57" else folder_seeds(target)).items():
            mixed["%02d_%s" % (hint, name)] = bytes([hint]) + data
    write("fuzz_read_cloud_bytes", mixed)
    grpc_seeds, json_seeds = request_seeds(ply, text)
    write("fuzz_grpc_request", grpc_seeds)
    write("fuzz_http_request", {**json_seeds, **http_header_seeds()})
    write("fuzz_health_request", health_request_seeds())
    return 0


if __name__ == "__main__":
    sys.exit(main())
