"""Tests of scripts/supervisor.py: the launch-file YAML subset, variable substitution, and the
process supervision (prefixed output, respawn, required processes, shutdown_after, SIGTERM then
SIGKILL, stop on a signal). Processes are small shell commands; waits are on process exit."""
import os
import signal
import subprocess
import sys
import tempfile
import time
import unittest

SOURCE = os.environ.get('MESHNAV_SOURCE_DIR', os.path.join(os.path.dirname(__file__), '..', '..'))
SUPERVISOR = os.path.join(SOURCE, 'scripts', 'supervisor.py')
sys.path.insert(0, os.path.join(SOURCE, 'scripts'))
import supervisor  # noqa: E402


def run_launch(text, *args, timeout=30):
    with tempfile.NamedTemporaryFile('w', suffix='.yaml', delete=False) as f:
        f.write(text)
        path = f.name
    try:
        p = subprocess.run([sys.executable, SUPERVISOR, path] + list(args), capture_output=True,
                           text=True, timeout=timeout)
        return p.returncode, p.stdout, p.stderr
    finally:
        os.unlink(path)


class YamlSubset(unittest.TestCase):
    def test_nested_document(self):
        doc = supervisor.load_yaml_subset('''
# a launch file
name: demo   # trailing comment
stop_timeout: 2.5
shutdown_after: [a, "b c"]
processes:
  - name: a
    command: /bin/echo
    args: [--url, "udpm://239.255.76.67:7667?ttl=0", 'it''s', 3, -1.5, true, "# not a comment"]
    env: {X: 1, Y: "two words"}
  - name: b c
    command: sleep 1
    required: yes
    args:
      - one
      - [nested, list]
  -
    name: d
    command: x
empty:
''')
        self.assertEqual(doc['name'], 'demo')
        self.assertEqual(doc['stop_timeout'], 2.5)
        self.assertEqual(doc['shutdown_after'], ['a', 'b c'])
        p = doc['processes']
        self.assertEqual(len(p), 3)
        self.assertEqual(p[0]['args'], ['--url', 'udpm://239.255.76.67:7667?ttl=0', "it's", 3, -1.5, True,
                                        '# not a comment'])
        self.assertEqual(p[0]['env'], {'X': 1, 'Y': 'two words'})
        self.assertIs(p[1]['required'], True)
        self.assertEqual(p[1]['args'], ['one', ['nested', 'list']])
        self.assertEqual(p[2], {'name': 'd', 'command': 'x'})
        self.assertIsNone(doc['empty'])

    def test_multiline_flow_and_list_at_key_indent(self):
        doc = supervisor.load_yaml_subset('a: [1,\n     2, {k: v,\n  w: [x]}]\nb:\n- p\n- q\n')
        self.assertEqual(doc, {'a': [1, 2, {'k': 'v', 'w': ['x']}], 'b': ['p', 'q']})

    def test_errors_name_the_line(self):
        for text, line in [('a: 1\n  b: 2\n', ':2'), ('a: [1, 2\nb: 3\n', ':1'), ('a: 1\na: 2\n', ':2'),
                           ('a:\n\tb: 1\n', ':2'), ('a: "open\n', ':1')]:
            with self.assertRaises(supervisor.LaunchError) as cm:
                supervisor.load_yaml_subset(text, 'f.yaml')
            self.assertIn('f.yaml' + line, str(cm.exception), text)

    def test_same_as_pyyaml_on_the_launch_files(self):
        try:
            import yaml
        except ImportError:
            self.skipTest('PyYAML is not installed')
        folder = os.path.join(SOURCE, 'config', 'launch')
        for name in sorted(os.listdir(folder)):
            if name.endswith('.yaml'):
                with open(os.path.join(folder, name)) as f:
                    text = f.read()
                self.assertEqual(supervisor.load_yaml_subset(text, name), yaml.safe_load(text), name)


class Substitution(unittest.TestCase):
    def test_variables_defaults_and_errors(self):
        v = {'A': 'x', 'B': ''}
        self.assertEqual(supervisor.substitute('${A}/${B}/${C:-d}/${A:-no}', v, 'w'), 'x//d/x')
        self.assertEqual(supervisor.substitute(['${A}', {'k': '${A}'}, 3], v, 'w'), ['x', {'k': 'x'}, 3])
        with self.assertRaises(supervisor.LaunchError) as cm:
            supervisor.substitute('${MISSING}', v, 'w')
        self.assertIn('MISSING', str(cm.exception))

    def test_builtin_t0(self):
        with tempfile.NamedTemporaryFile('w', suffix='.yaml', delete=False) as f:
            f.write('t0_margin: 2\nprocesses:\n  - {name: a, command: "echo ${T0_UTIME}"}\n')
        try:
            launch = supervisor.Launch(f.name, {})
            t0 = int(launch.procs[0].argv[1])
            self.assertAlmostEqual(t0 / 1e6, time.time() + 2.0, delta=1.0)
            self.assertEqual(supervisor.Launch(f.name, {'T0_UTIME': '5'}).procs[0].argv[1], '5')
        finally:
            os.unlink(f.name)

    def test_launch_files_expand(self):
        folder = os.path.join(SOURCE, 'config', 'launch')
        for name in sorted(os.listdir(folder)):
            if name.endswith('.yaml'):
                rc = subprocess.run([sys.executable, SUPERVISOR, os.path.join(folder, name), '--dry-run',
                                     'DATASET=/d', 'OUT=/o', 'LOG=/l', 'SETUP=/s', 'DEVICE=/dev/null'],
                                    capture_output=True, text=True)
                self.assertEqual(rc.returncode, 0, name + rc.stderr)

    def test_bad_launch_files(self):
        for text, msg in [('processes: []\n', 'non-empty'),
                          ('processes:\n  - {name: a}\n', "needs 'command'"),
                          ('processes:\n  - {name: a, command: x, bogus: 1}\n', 'bogus'),
                          ('processes:\n  - {name: a, command: x}\n  - {name: a, command: y}\n', 'duplicate'),
                          ('shutdown_after: [z]\nprocesses:\n  - {name: a, command: x}\n', "'z'"),
                          ('processes:\n  - {name: a, command: "${NOPE}"}\n', 'NOPE'),
                          # found by fuzz/launch_yaml_fuzz.py: these raised TypeError/ValueError
                          ('stop_timeout:\nprocesses:\n  - {name: a, command: x}\n', 'stop_timeout must be a number'),
                          ('processes:\n  - {name: a, command: x, delay: soon}\n', 'delay must be a number'),
                          ('processes:\n  - {name: a, command: x, max_respawns: -2}\n', 'max_respawns must be a number >= -1'),
                          ('processes:\n  - {name: a, command: x, env: [1]}\n', 'env of a must be a map')]:
            rc, out, err = run_launch(text)
            self.assertEqual(rc, 2, text)
            self.assertIn(msg, err, text)

    def test_launch_file_not_utf8(self):
        # found by fuzz/launch_yaml_fuzz.py: a UnicodeDecodeError traceback before
        with tempfile.NamedTemporaryFile('wb', suffix='.yaml', delete=False) as f:
            f.write(b'processes:\n  - {name: a, command: "\xbf\xff"}\n')
            path = f.name
        try:
            p = subprocess.run([sys.executable, SUPERVISOR, path, '--dry-run'], capture_output=True, text=True)
        finally:
            os.unlink(path)
        self.assertEqual(p.returncode, 2, p.stderr)
        self.assertIn(path + ': not UTF-8 text (byte', p.stderr)


class Supervision(unittest.TestCase):
    def test_prefix_respawn_and_shutdown_after(self):
        rc, out, _ = run_launch('''
stop_timeout: 2
shutdown_after: [worker]
shutdown_delay: 0.2
processes:
  - name: server
    command: sleep 60
    required: true
  - name: flaky
    command: sh -c 'echo flaky up; exit 3'
    respawn: true
    respawn_delay: 0.05
    max_respawns: 2
  - name: worker
    command: sh -c 'echo out; echo err >&2; sleep 1; echo ${GREETING:-hi}'
''', 'GREETING=bye')
        self.assertEqual(rc, 0, out)
        self.assertIn('[worker] out\n', out)
        self.assertIn('[worker] err\n', out)
        self.assertIn('[worker] bye\n', out)
        self.assertEqual(out.count('[flaky] flaky up'), 3)  # first run + 2 respawns
        self.assertIn('no more respawns', out)
        self.assertIn('stopping (every shutdown_after process has exited)', out)
        self.assertIn('[supervisor] server exited', out)

    def test_required_failure_stops_all_and_fails(self):
        t = time.monotonic()
        rc, out, _ = run_launch('''
processes:
  - name: long
    command: sleep 60
  - name: core
    command: sh -c 'sleep 0.2; exit 4'
    required: true
''')
        self.assertEqual(rc, 1, out)
        self.assertIn('FAILED: core (exit code 4)', out)
        self.assertIn('[supervisor] long exited', out)
        self.assertLess(time.monotonic() - t, 20)

    def test_required_clean_exit_stops_all_and_succeeds(self):
        rc, out, _ = run_launch('''
processes:
  - {name: long, command: sleep 60}
  - {name: core, command: "sh -c 'exit 0'", required: true}
''')
        self.assertEqual(rc, 0, out)
        self.assertIn('required process core exited', out)

    def test_sigkill_after_stop_timeout(self):
        rc, out, _ = run_launch('''
stop_timeout: 0.5
processes:
  - name: stubborn
    command: sh -c 'trap "" TERM; echo ready; while true; do sleep 0.1; done'
  - name: trigger
    command: sh -c 'sleep 0.3'
    required: true
''')
        self.assertIn('SIGKILL to stubborn', out)
        self.assertEqual(rc, 0, out)  # stubborn is neither required nor in shutdown_after

    def test_failed_shutdown_after_process_fails_the_launch(self):
        rc, out, _ = run_launch('''
shutdown_after: [job]
processes:
  - {name: job, command: "sh -c 'exit 2'"}
  - {name: bg, command: sleep 60}
''')
        self.assertEqual(rc, 1, out)
        self.assertIn('FAILED: job (exit code 2)', out)

    def test_missing_binary(self):
        rc, out, _ = run_launch('processes:\n  - {name: ghost, command: /nonexistent/bin, required: true}\n')
        self.assertEqual(rc, 1, out)
        self.assertIn('cannot start ghost', out)

    def test_sigterm_stops_everything(self):
        with tempfile.NamedTemporaryFile('w', suffix='.yaml', delete=False) as f:
            f.write('processes:\n  - {name: a, command: "sh -c \'echo started; exec sleep 60\'"}\n'
                    '  - {name: b, command: sleep 60, required: true}\n')
        try:
            p = subprocess.Popen([sys.executable, SUPERVISOR, f.name], stdout=subprocess.PIPE, text=True)
            for line in p.stdout:  # wait for a condition: the child is up
                if '[a] started' in line:
                    break
            p.send_signal(signal.SIGTERM)
            rest = p.stdout.read()
            p.stdout.close()
            self.assertEqual(p.wait(timeout=20), 0, rest)
            self.assertIn('stopping (signal 15)', rest)
            self.assertIn('[supervisor] b exited', rest)
        finally:
            os.unlink(f.name)


if __name__ == '__main__':
    unittest.main()
