#!/usr/bin/env python3
"""An independent client: Python stubs generated at test time from the .proto files register the bunny
pair against the real k4reg-server and check the standard health and reflection services.

usage: python_client_test.py --server BIN --proto-dir DIR --grpc-proto-dir DIR --data-dir DIR
Needs python3-grpcio and python3-protobuf, protoc and grpc_python_plugin (Debian packages)."""
import argparse
import math
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time


def generate_stubs(out_dir, proto_dir, grpc_proto_dir):
    plugin = shutil.which("grpc_python_plugin")
    if plugin is None:
        sys.exit("grpc_python_plugin not found (Debian package protobuf-compiler-grpc)")
    # Generated under grpc/... the modules would hide behind the installed grpc package: give them other
    # module paths (the proto packages, and so the service names on the wire, stay grpc.health.v1 and
    # grpc.reflection.v1alpha).
    renamed = {"grpc_health_v1": "grpc/health/v1/health.proto",
               "grpc_reflection_v1alpha": "grpc/reflection/v1alpha/reflection.proto"}
    for module, proto in renamed.items():
        os.makedirs(os.path.join(out_dir, "protos", module))
        shutil.copy(os.path.join(grpc_proto_dir, proto), os.path.join(out_dir, "protos", module))
    subprocess.run(["protoc", f"-I{proto_dir}", f"-I{os.path.join(out_dir, 'protos')}", f"--python_out={out_dir}",
                    f"--grpc_out={out_dir}", f"--plugin=protoc-gen-grpc={plugin}", "k4reg/v1/registration.proto"]
                   + [f"{module}/{os.path.basename(proto)}" for module, proto in renamed.items()], check=True)
    sys.path.insert(0, out_dir)


def start_server(binary, data_dir, work_dir):
    port_file = os.path.join(work_dir, "port")
    log = open(os.path.join(work_dir, "server.log"), "w")
    process = subprocess.Popen([binary, "--grpc-listen", "127.0.0.1:0", "--port-file", port_file,
                                "--http-listen", "", "--data-root", data_dir, "--workers", "1",
                                "--spool-dir", work_dir, "--reflection"],
                               stderr=log)
    deadline = time.monotonic() + 20
    while not os.path.exists(port_file):
        if process.poll() is not None or time.monotonic() > deadline:
            sys.exit("k4reg-server did not start: " + open(log.name).read())
        time.sleep(0.05)
    return process, int(open(port_file).read())


def read_ground_truth(data_dir, source, target):
    lines = [l for l in open(os.path.join(data_dir, "gt_pairs.log")) if l.strip() and not l.startswith("#")]
    for i, line in enumerate(lines):
        if line.split()[:2] == [source, target]:
            return [float(v) for row in lines[i + 1:i + 5] for v in row.split()]
    sys.exit(f"{source} {target} not in gt_pairs.log")


def main():
    parser = argparse.ArgumentParser()
    for name in ("--server", "--proto-dir", "--grpc-proto-dir", "--data-dir"):
        parser.add_argument(name, required=True)
    args = parser.parse_args()

    with tempfile.TemporaryDirectory(prefix="k4reg-py-") as work_dir:
        generate_stubs(work_dir, args.proto_dir, args.grpc_proto_dir)
        import grpc
        from grpc_health_v1 import health_pb2, health_pb2_grpc
        from grpc_reflection_v1alpha import reflection_pb2, reflection_pb2_grpc
        from k4reg.v1 import registration_pb2, registration_pb2_grpc

        server, port = start_server(args.server, args.data_dir, work_dir)
        try:
            channel = grpc.insecure_channel(f"127.0.0.1:{port}")
            health = health_pb2_grpc.HealthStub(channel)
            for service in ("", "liveness", "readiness"):
                reply = health.Check(health_pb2.HealthCheckRequest(service=service), timeout=10)
                assert reply.status == health_pb2.HealthCheckResponse.SERVING, (service, reply)

            reflection = reflection_pb2_grpc.ServerReflectionStub(channel)
            answers = reflection.ServerReflectionInfo(iter([reflection_pb2.ServerReflectionRequest(list_services="")]),
                                                      timeout=10)
            services = {s.name for answer in answers for s in answer.list_services_response.service}
            assert {"k4reg.v1.Registration", "grpc.health.v1.Health"} <= services, services

            stub = registration_pb2_grpc.RegistrationStub(channel)
            request = registration_pb2.RegisterRequest(
                source=registration_pb2.CloudInput(path="bun045.ply"),
                target=registration_pb2.CloudInput(path="bun000.ply"),
                params=registration_pb2.RegistrationParams(min_scale_m=0.001, overlap=0.9))
            reply, call = stub.Register.with_call(request, timeout=120, metadata=[("x-request-id", "py-client-1")])
            result = reply.result
            assert len(result.transform) == 16
            truth = read_ground_truth(args.data_dir, "bun045.ply", "bun000.ply")
            translation_error = math.dist([result.transform[i] for i in (3, 7, 11)], [truth[i] for i in (3, 7, 11)])
            rotation_error = max(abs(result.transform[i] - truth[i]) for i in (0, 1, 2, 4, 5, 6, 8, 9, 10))
            assert translation_error < 0.005, translation_error
            assert rotation_error < 0.02, rotation_error
            assert result.seed == 42 and result.icp_converged, result
            assert reply.request_id == "py-client-1", reply.request_id
            assert ("x-request-id", "py-client-1") in call.initial_metadata()
            assert reply.server.version and reply.server.server_id
            assert reply.timings.registration_s > 0
            print(f"registered bun045 -> bun000 on {reply.server.server_id}: rmse {result.rmse_m:.5f} m, "
                  f"translation error {translation_error * 1000:.2f} mm")

            # A project: three scans into bun000's frame, events as they come, the result last.
            project = registration_pb2.RegisterProjectRequest(
                scans=[registration_pb2.CloudInput(path=name) for name in ("bun000.ply", "bun045.ply", "bun315.ply")],
                params=registration_pb2.ProjectParams(
                    pairwise=registration_pb2.RegistrationParams(min_scale_m=0.002, overlap=0.5, seed=1)))
            pairs, final = 0, None
            for event in stub.RegisterProject(project, timeout=180):
                kind = event.WhichOneof("event")
                pairs += kind == "pair"
                if kind == "result":
                    final = event.result.result
            assert pairs == 3 and final is not None, (pairs, final)
            assert [scan.registered for scan in final.scans] == [True, True, True], final.scans
            assert list(final.scans[0].pose) == [1.0, 0, 0, 0, 0, 1.0, 0, 0, 0, 0, 1.0, 0, 0, 0, 0, 1.0]
            truth = read_ground_truth(args.data_dir, "bun045.ply", "bun000.ply")
            pose = final.scans[1].pose
            assert math.dist([pose[i] for i in (3, 7, 11)], [truth[i] for i in (3, 7, 11)]) < 0.002, list(pose)
            print(f"project of 3 scans: {final.scans_registered} registered, global rmse {final.global_rmse_m:.5f} m")

            try:
                stub.Register(registration_pb2.RegisterRequest(
                    source=registration_pb2.CloudInput(path="../bunny/bun045.ply"),
                    target=registration_pb2.CloudInput(path="/etc/passwd")), timeout=10)
                sys.exit("a path outside the data root was accepted")
            except grpc.RpcError as error:
                assert error.code() == grpc.StatusCode.PERMISSION_DENIED, error
            channel.close()  # an open connection would hold the server's shutdown until its deadline
        finally:
            server.send_signal(signal.SIGTERM)
            code = server.wait(timeout=60)
        assert code == 0, f"server exit code {code}"
        print("python client: OK")


if __name__ == "__main__":
    main()
