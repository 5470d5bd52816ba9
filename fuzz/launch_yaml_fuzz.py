#!/usr/bin/env python3
"""Fuzzing of the launch-file parser of scripts/supervisor.py (a YAML subset in Python, so no
libFuzzer): deterministic random mutations of the seed launch files (fuzz/corpus/launch_yaml/),
random bytes included, each loaded as a launch file with Launch(path, {}). A refusal is a
LaunchError naming the file; any other exception is a finding: the input is saved to --save DIR
as launch_yaml-<seed>-<n>.yaml and the script exits 1.

    launch_yaml_fuzz.py [--iterations N | --seconds S] [--seed S] [--save DIR] SEED_FILE|DIR...
"""
import argparse
import os
import random
import sys
import tempfile
import time
import traceback

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'scripts'))
import supervisor  # noqa: E402

# Tokens at the edges of the YAML subset and of the values the supervisor converts.
TOKENS = [b'[', b']', b'{', b'}', b',', b':', b': ', b'- ', b'#', b'"', b"'", b'\\', b'\t', b'\n',
          b'\r\n', b'  ', b'---', b'~', b'null', b'true', b'1e308', b'nan', b'-1', b'${', b'${X}',
          b'}', b'&a', b'*a', b'|', b'>', b'processes:', b'respawn: true', b'required: true',
          b'\xff\xfe', b'\x00', b'stop_timeout: x', b'args: 5', b'env: [1]']


def mutate(rng, data, other):
    s = bytearray(data)
    for _ in range(rng.randint(1, 4)):
        pos = rng.randint(0, len(s))
        op = rng.randrange(8)
        if op == 0 and s:
            s[rng.randrange(len(s))] ^= 1 << rng.randrange(8)
        elif op == 1 and s:
            s[rng.randrange(len(s))] = rng.randrange(256)
        elif op == 2:
            s[pos:pos] = bytes(rng.randrange(256) for _ in range(rng.randint(1, 4)))
        elif op == 3 and s:
            i = rng.randrange(len(s))
            del s[i:i + rng.randint(1, 16)]
        elif op == 4:
            s[pos:pos] = rng.choice(TOKENS)
        elif op == 5 and s:
            i = rng.randrange(len(s))
            s[pos:pos] = s[i:i + rng.randint(1, 64)]
        elif op == 6:
            del s[rng.randint(0, len(s)):]
        elif other:
            i = rng.randrange(len(other))
            s[pos:pos] = other[i:i + rng.randint(1, 128)]
    return bytes(s)


def check(path):
    """Loads one launch file; returns None, or the traceback of a finding."""
    try:
        launch = supervisor.Launch(path, {})
        for p in launch.procs:
            assert p.argv and all(isinstance(a, str) for a in p.argv), 'process without a command line'
    except supervisor.LaunchError as e:
        if path not in str(e):
            return 'LaunchError without the file name: %s' % e
    except Exception:  # noqa: BLE001  (anything else is what we look for)
        return traceback.format_exc()
    return None


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--iterations', type=int, default=0)
    ap.add_argument('--seconds', type=float, default=0.0)
    ap.add_argument('--seed', type=int, default=1)
    ap.add_argument('--save', default='.')
    ap.add_argument('inputs', nargs='+')
    a = ap.parse_args(argv)
    files = []
    for p in a.inputs:
        files += sorted(os.path.join(p, f) for f in os.listdir(p)) if os.path.isdir(p) else [p]
    corpus = [open(f, 'rb').read() for f in files]
    if not corpus:
        print('no seed files (an empty corpus tests nothing)', file=sys.stderr)
        return 2
    rng = random.Random(a.seed)
    deadline = time.monotonic() + a.seconds if a.seconds > 0 else None
    with tempfile.TemporaryDirectory(prefix='meshnav-fuzz-') as tmp:
        path = os.path.join(tmp, 'launch.yaml')
        n = 0
        while True:
            if deadline is None and n >= len(corpus) + a.iterations:
                break
            if deadline is not None and time.monotonic() >= deadline and n >= len(corpus):
                break
            if n < len(corpus):
                data = corpus[n]
            elif rng.randrange(20) == 0:
                data = bytes(rng.randrange(256) for _ in range(rng.randint(0, 200)))
            else:
                data = mutate(rng, rng.choice(corpus), rng.choice(corpus))
            with open(path, 'wb') as f:
                f.write(data)
            finding = check(path)
            if finding:
                out = os.path.join(a.save, 'launch_yaml-%d-%d.yaml' % (a.seed, n))
                with open(out, 'wb') as f:
                    f.write(data)
                print('fuzz finding (input saved as %s):\n%s' % (out, finding), file=sys.stderr)
                return 1
            n += 1
    print('%d inputs (seed %d): no finding' % (n, a.seed))
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
