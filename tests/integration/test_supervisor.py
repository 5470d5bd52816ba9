"""Tests of scripts/supervisor.py: launch-file reading (yaml.safe_load, errors with file:line),
variable substitution, and the process supervision (prefixed output, respawn with its limit and
back-off, required processes, shutdown_after, SIGTERM then SIGKILL, stop on a signal), and the
respawn / required settings of the shipped launch files. Processes are small shell commands;
waits are on process exit or on a line of output."""
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


def run_until_then_sigterm(text, marker):
    """Starts the supervisor on launch text `text`, reads its output until a line holding `marker`
    (a condition, not a sleep), sends it SIGTERM. Returns (lines up to the marker, whether it was
    still running then, exit code, output after the signal)."""
    with tempfile.NamedTemporaryFile('w', suffix='.yaml', delete=False) as f:
        f.write(text)
    try:
        p = subprocess.Popen([sys.executable, SUPERVISOR, f.name], stdout=subprocess.PIPE, text=True)
        seen = []
        for line in p.stdout:
            seen.append(line)
            if marker in line:
                break
        running = p.poll() is None
        p.send_signal(signal.SIGTERM)
        rest = p.stdout.read()
        p.stdout.close()
        return seen, running, p.wait(timeout=20), rest
    finally:
        os.unlink(f.name)


class LaunchYaml(unittest.TestCase):
    def test_launch_file_is_read_as_yaml(self):
        doc = supervisor.load_yaml('''
# a launch file
name: demo   # trailing comment
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
empty:
''')
        self.assertEqual(doc['shutdown_after'], ['a', 'b c'])
        p = doc['processes']
        self.assertEqual(p[0]['args'], ['--url', 'udpm://239.255.76.67:7667?ttl=0', "it's", 3, -1.5, True,
                                        '# not a comment'])
        self.assertEqual(p[0]['env'], {'X': 1, 'Y': 'two words'})
        self.assertIs(p[1]['required'], True)
        self.assertEqual(p[1]['args'], ['one', ['nested', 'list']])
        self.assertIsNone(doc['empty'])

    def test_errors_name_the_line(self):
        for text, line in [('a: 1\n  b: 2\n', ':2'), ('a: [1, 2\nb: 3\n', ':2'), ('a: 1\na: 2\n', ':2'),
                           ('x: 0\na:\n\tb: 1\n', ':3'), ('a: "open\n', ':2')]:
            with self.assertRaises(supervisor.LaunchError) as cm:
                supervisor.load_yaml(text, 'f.yaml')
            self.assertIn('f.yaml' + line + ':', str(cm.exception), text)

    def test_duplicate_key_is_refused(self):
        with self.assertRaises(supervisor.LaunchError) as cm:
            supervisor.load_yaml('processes:\n  - {name: a, command: x, name: b}\n', 'f.yaml')
        self.assertIn("duplicate key 'name'", str(cm.exception))


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
                          ('processes:\n  - {name: a, command: x, respawn: sometimes}\n', 'respawn must be'),
                          ('processes:\n  - {name: a, command: x, max_respawns: 1.5}\n', 'max_respawns'),
                          ('processes:\n  - {name: a, command: x, respawn_delay: -1}\n', 'respawn_delay'),
                          ('processes:\n  - {name: a, command: x, required: maybe}\n', 'required'),
                          # found by fuzz/launch_yaml_fuzz.py: these raised TypeError/ValueError
                          ('stop_timeout:\nprocesses:\n  - {name: a, command: x}\n', 'stop_timeout must be a number'),
                          ('processes:\n  - {name: a, command: x, delay: soon}\n', 'delay must be a number'),
                          ('processes:\n  - {name: a, command: x, delay: "${D:-nan}"}\n', 'delay must be a number'),
                          ('processes:\n  - {name: a, command: x, max_respawns: -2}\n', 'max_respawns must be an integer >= -1'),
                          ('processes:\n  - {name: a, command: x, env: [1]}\n', 'env must be a map'),
                          # 600 s fuzz run 2026-11-26: a key that YAML reads as a bool raised TypeError
                          ('yes: 1\nprocesses:\n  - {name: a, command: x}\n', 'unknown key(s) True'),
                          ('processes:\n  - {name: a, command: x, 3: y}\n', 'unknown process key(s) 3')]:
            rc, out, err = run_launch(text)
            self.assertEqual(rc, 2, text)
            self.assertIn(msg, err, text)

    def test_number_from_a_variable(self):
        # config/launch/fly.yaml: respawn_delay: ${ESTIMATOR_RESPAWN_DELAY:-0.2}
        text = 'processes:\n  - {name: a, command: x, respawn: on-failure, respawn_delay: "${D:-0.2}"}\n'
        rc, out, err = run_launch(text, 'D=1.5', '--dry-run')
        self.assertEqual(rc, 0, err)
        rc, out, err = run_launch(text, 'D=later', '--dry-run')
        self.assertEqual(rc, 2, err)
        self.assertIn('respawn_delay must be a number', err)

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

    @staticmethod
    def _chatty_launch(core_exit):
        """A launch file whose 'chatty' process writes 2000 lines, and whose required 'core' exits
        with `core_exit` after 1 s; returns its path (the caller removes it)."""
        with tempfile.NamedTemporaryFile('w', suffix='.yaml', delete=False) as f:
            f.write('''
processes:
  - {name: chatty, command: "sh -c 'i=0; while [ $i -lt 2000 ]; do echo line $i; i=$((i+1)); done; sleep 60'"}
  - {name: core, command: "sh -c 'sleep 1; exit %d'", required: true}
''' % core_exit)
        return f.name

    def test_a_closed_stdout_does_not_stop_the_supervision(self):
        # Issue 36: `./meshnav up ... | head -1` used to raise BrokenPipeError in say(): the run
        # aborted, or an output thread died and its process's exit was never seen. Now the lines are
        # dropped, stderr says so once, and the required process's exit still ends the run with 0.
        launch = self._chatty_launch(0)
        try:
            p = subprocess.Popen([sys.executable, SUPERVISOR, launch], stdout=subprocess.PIPE,
                                 stderr=subprocess.PIPE, text=True)
            first = p.stdout.readline()  # the reader takes one line and goes away, as `head -1`
            p.stdout.close()
            rc = p.wait(timeout=30)
            err = p.stderr.read()
            p.stderr.close()
        finally:
            os.unlink(launch)
        self.assertIn('[supervisor]', first)
        self.assertEqual(rc, 0, err)
        self.assertIn('supervisor: output lost', err)
        self.assertNotIn('Traceback', err)

    def test_a_full_disk_on_stdout_does_not_stop_the_supervision(self):
        # Issue 36: with stdout on a full disk the output threads died, exit events were lost and
        # the run hung for good. /dev/full fails every write with ENOSPC, as a full disk does.
        launch = self._chatty_launch(3)
        try:
            with open('/dev/full', 'w') as full:
                p = subprocess.run([sys.executable, SUPERVISOR, launch], stdout=full, stderr=subprocess.PIPE,
                                   text=True, timeout=30)
        finally:
            os.unlink(launch)
        self.assertIn('supervisor: output lost ([Errno 28]', p.stderr)
        self.assertNotIn('Traceback', p.stderr)
        self.assertNotEqual(p.returncode, 0, p.stderr)  # the required process's failure still counts

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

    def test_stop_last_is_stopped_once_the_others_have_exited(self):
        # A logger in stop_last records what the others publish on their way out (issue 35: the
        # estimator's last POSE_SMOOTHED).
        rc, out, _ = run_launch('''
stop_timeout: 3
stop_last: [logger]
processes:
  - name: logger
    command: sh -c 'trap "echo logger got TERM; exit 0" TERM; echo ready; while true; do sleep 0.05; done'
  - name: pub
    command: sh -c 'trap "sleep 0.3; echo pub done; exit 0" TERM; while true; do sleep 0.05; done'
  - name: trigger
    command: sh -c 'sleep 0.5'
    required: true
''')
        self.assertEqual(rc, 0, out)
        self.assertIn('[logger] logger got TERM', out)
        self.assertLess(out.index('[pub] pub done'), out.index('[logger] logger got TERM'), out)
        self.assertIn('SIGTERM to logger (stop_last', out)

    def test_stop_last_follows_a_process_killed_after_stop_timeout(self):
        rc, out, _ = run_launch('''
stop_timeout: 0.5
stop_last: [logger]
processes:
  - name: logger
    command: sh -c 'trap "echo logger got TERM; exit 0" TERM; while true; do sleep 0.05; done'
  - name: stubborn
    command: sh -c 'trap "" TERM; while true; do sleep 0.1; done'
  - name: trigger
    command: sh -c 'sleep 0.3'
    required: true
''')
        self.assertEqual(rc, 0, out)
        self.assertIn('SIGKILL to stubborn', out)
        self.assertLess(out.index('SIGKILL to stubborn'), out.index('[logger] logger got TERM'), out)

    def test_stop_last_must_name_a_process(self):
        rc, out, err = run_launch('stop_last: [ghost]\nprocesses:\n  - {name: a, command: sleep 1}\n')
        self.assertEqual(rc, 2, out + err)
        self.assertIn("stop_last names unknown process 'ghost'", out + err)

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
        _, running, rc, rest = run_until_then_sigterm(
            'processes:\n  - {name: a, command: "sh -c \'echo started; exec sleep 60\'"}\n'
            '  - {name: b, command: sleep 60, required: true}\n', '[a] started')
        self.assertTrue(running)
        self.assertEqual(rc, 0, rest)
        self.assertIn('stopping (signal 15)', rest)
        self.assertIn('[supervisor] b exited', rest)


class Respawn(unittest.TestCase):
    """respawn / required semantics: restarts up to the limit with a doubling back-off, a clean exit
    not restarted under on-failure, a required process stopping all only once it is gone for good,
    a process that is not required failing for good while the others go on."""

    def test_on_failure_restarts_up_to_the_limit_with_back_off(self):
        rc, out, _ = run_launch('''
processes:
  - name: flaky
    command: sh -c 'echo run; exit 3'
    respawn: on-failure
    respawn_delay: 0.01
    respawn_delay_max: 0.03
    max_respawns: 3
''')
        self.assertEqual(rc, 0, out)  # not required: its failure does not fail the launch
        self.assertEqual(out.count('[flaky] run'), 4, out)  # first run + 3 restarts
        delays = [line.split(' in ')[1] for line in out.splitlines() if 'restarting flaky in' in line]
        self.assertEqual(delays, ['0.01 s', '0.02 s', '0.03 s'])  # doubled, capped by respawn_delay_max
        self.assertIn('flaky: no more respawns (max_respawns 3)', out)

    def test_on_failure_does_not_restart_a_clean_exit(self):
        rc, out, _ = run_launch('''
processes:
  - {name: done, command: "sh -c 'echo run; exit 0'", respawn: on-failure, respawn_delay: 0.01}
  - {name: killed, command: "sh -c 'echo run; kill -9 $$'", respawn: on-failure, respawn_delay: 0.01,
     max_respawns: 1}
''')
        self.assertEqual(rc, 0, out)
        self.assertEqual(out.count('[done] run'), 1, out)
        self.assertEqual(out.count('[killed] run'), 2, out)  # death by a signal is a failure
        self.assertIn('killed exited (signal 9)', out)

    def test_required_process_is_restarted_before_it_stops_all(self):
        rc, out, _ = run_launch('''
processes:
  - {name: long, command: sleep 60, respawn: on-failure}
  - name: core
    command: sh -c 'echo core up; exit 4'
    required: true
    respawn: on-failure
    respawn_delay: 0.01
    max_respawns: 2
''')
        self.assertEqual(rc, 1, out)
        self.assertEqual(out.count('[core] core up'), 3, out)
        self.assertEqual(out.count('required process core exited'), 1, out)
        self.assertLess(out.index('core: no more respawns'), out.index('stopping (required process core exited)'))
        self.assertIn('FAILED: core (exit code 4)', out)
        self.assertIn('[supervisor] long exited', out)
        self.assertNotIn('restarting long', out)  # stopped by the supervisor: not restarted

    def test_a_process_that_is_not_required_gives_up_while_the_others_run(self):
        seen, running, rc, rest = run_until_then_sigterm('''
processes:
  - {name: nav, command: "sh -c 'echo nav up; exec sleep 60'", required: true, respawn: on-failure}
  - name: calib
    command: sh -c 'echo calib up; exit 1'
    respawn: on-failure
    respawn_delay: 0.01
    max_respawns: 2
''', 'calib: no more respawns')  # the condition: calib has given up
        self.assertIn('[supervisor] calib: no more respawns (max_respawns 2)\n', seen)
        self.assertEqual(sum('[calib] calib up' in line for line in seen), 3, seen)
        self.assertFalse(any('nav exited' in line or 'stopping' in line for line in seen), seen)
        self.assertTrue(running)  # the supervisor and nav still ran
        self.assertEqual(rc, 0, rest)
        self.assertIn('stopping (signal 15)', rest)
        self.assertIn('[supervisor] nav exited', rest)

    def test_shutdown_after_waits_for_the_last_restart(self):
        rc, out, _ = run_launch('''
shutdown_after: [job]
shutdown_delay: 0
processes:
  - {name: bg, command: sleep 60}
  - {name: job, command: "sh -c 'echo job run; exit 5'", respawn: on-failure, respawn_delay: 0.01,
     max_respawns: 2}
''')
        self.assertEqual(rc, 1, out)
        self.assertEqual(out.count('[job] job run'), 3, out)
        self.assertLess(out.index('job: no more respawns'), out.index('stopping (every shutdown_after'))


class ShippedLaunchFiles(unittest.TestCase):
    """config/launch/*.yaml: every process is restarted after a crash with a limit, the estimator
    is required, the calibrator is not (a calibrator crash must not stop navigation)."""

    def test_respawn_and_required(self):
        folder = os.path.join(SOURCE, 'config', 'launch')
        variables = {'DATASET': '/d', 'OUT': '/o', 'LOG': '/l', 'SETUP': '/s', 'DEVICE': '/dev/null'}
        names = sorted(n for n in os.listdir(folder) if n.endswith('.yaml'))
        self.assertGreaterEqual(len(names), 5)
        for name in names:
            launch = supervisor.Launch(os.path.join(folder, name), variables)
            for p in launch.procs:
                where = '%s: %s' % (name, p.name)
                if p.name == 'vehicle_sim':  # fly.yaml: the simulated world; restarted it is another flight
                    self.assertEqual(p.respawn, 'never', where)
                    continue
                self.assertNotEqual(p.respawn, 'never', where)
                if p.max_respawns < 0:  # unlimited only with a bounded back-off
                    self.assertLessEqual(p.respawn_delay_max, 30.0, where)
                    self.assertGreater(p.respawn_delay, 0.0, where)
                if p.name == 'estimator':
                    self.assertTrue(p.required, where)
                if p.name in ('calibrator', 'mission'):
                    self.assertFalse(p.required, where)


class Hosts(unittest.TestCase):
    """host: per process, --host NAME, --list-hosts (multi-host launch files, docs/deployment.md)."""
    TEXT = '''
shutdown_after: [a_bridge, u_bridge]
shutdown_delay: 0.1
processes:
  - {name: u_main, host: uav, command: sleep 60, required: true}
  - {name: u_bridge, host: uav, command: "sh -c 'echo uav bridge done'"}
  - {name: a_bridge, host: anchor1, command: "sh -c 'echo anchor bridge done'"}
  - {name: g_log, host: ground, command: sleep 60}
'''

    def test_list_hosts_says_which_stop_by_themselves(self):
        rc, out, err = run_launch(self.TEXT, '--list-hosts')
        self.assertEqual(rc, 0, err)
        self.assertEqual(out.split('\n')[:3], ['uav stops', 'anchor1 stops', 'ground runs'])

    def test_host_starts_only_its_processes_and_stops_on_its_shutdown_after(self):
        rc, out, _ = run_launch(self.TEXT, '--host', 'uav')
        self.assertEqual(rc, 0, out)
        self.assertIn('[u_bridge] uav bridge done', out)
        self.assertNotIn('a_bridge', out)  # another host's shutdown_after process is not waited for
        self.assertNotIn('g_log', out)
        self.assertIn('stopping (every shutdown_after process has exited)', out)
        rc, out, _ = run_launch(self.TEXT, '--host', 'anchor1', '--dry-run')
        self.assertEqual(rc, 0, out)
        self.assertEqual(out.strip().split('\n'), ["a_bridge@anchor1: sh -c 'echo anchor bridge done'"])

    def test_a_host_without_shutdown_after_runs_until_stopped(self):
        with tempfile.NamedTemporaryFile('w', suffix='.yaml', delete=False) as f:
            f.write(self.TEXT)
        try:
            p = subprocess.Popen([sys.executable, SUPERVISOR, f.name, '--host', 'ground'], stdout=subprocess.PIPE,
                                 text=True)
            for line in p.stdout:
                if 'started g_log' in line:
                    break
            self.assertIsNone(p.poll())
            p.send_signal(signal.SIGTERM)
            rest = p.stdout.read()
            p.stdout.close()
            self.assertEqual(p.wait(timeout=20), 0, rest)
        finally:
            os.unlink(f.name)

    def test_unknown_host_and_bad_host_names_are_refused(self):
        rc, _, err = run_launch(self.TEXT, '--host', 'nowhere')
        self.assertEqual(rc, 2)
        self.assertIn("no process has host 'nowhere' (hosts: uav, anchor1, ground)", err)
        rc, _, err = run_launch('processes: [{name: x, command: "true", host: "a b"}]', '--dry-run')
        self.assertEqual(rc, 2)
        self.assertIn('host must be a name', err)
        rc, _, err = run_launch(self.TEXT, '--host')
        self.assertEqual(rc, 2)
        self.assertIn('--host needs a host name', err)

    def test_shipped_multihost_file_has_a_host_per_anchor_the_uav_and_the_ground(self):
        launch = supervisor.Launch(os.path.join(SOURCE, 'config', 'launch', 'multihost.yaml'),
                                   {'DATASET': '/d', 'OUT': '/o'})
        hosts = launch.hosts()
        self.assertGreaterEqual(len(hosts), 7)
        self.assertEqual({p.host for p in launch.procs if p.name in ('estimator', 'calibrator', 'imu_bridge')},
                         {'uav'})
        self.assertEqual({p.host for p in launch.procs if p.name in ('mission', 'logging')}, {'ground'})
        for h in [h for h in hosts if h.startswith('anchor')]:
            procs = [p for p in launch.procs if p.host == h]
            self.assertEqual(len(procs), 1, h)
            self.assertIn('--initiators', procs[0].argv)
            self.assertEqual(procs[0].argv[procs[0].argv.index('--initiators') + 1], h[len('anchor'):])
        self.assertTrue(all(p.host for p in launch.procs))


if __name__ == '__main__':
    unittest.main()
