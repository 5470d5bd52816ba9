#!/usr/bin/env python3
"""Measures the live view (docs/view.md, "Measured"): view_server plays an .lcmlog at --speed, headless
Chromium opens the page with ?perf=1, and the page posts once a second how many animation frames it
drew (and the time of its first frame with the vehicle, from the moment it was opened). Prints the
time to the first frame and the frame rate while the log played (minimum, median, mean over 1 s
windows). A measurement, not a test: it asserts nothing.

  scripts/view_measure.py --log FILE.lcmlog [--speed 10] [--setup setup.yaml] [--bin build/bin] [--chromium chromium]
"""
import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import threading
import time


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--log', required=True, help='the .lcmlog to play')
    ap.add_argument('--speed', type=float, default=10.0, help='playback speed factor')
    ap.add_argument('--bin', default=os.path.join(os.path.dirname(__file__), '..', 'build', 'bin'))
    ap.add_argument('--chromium', default=shutil.which('chromium') or 'chromium')
    ap.add_argument('--window', default='1280,800', help='browser window size W,H [px]')
    ap.add_argument('--setup', help="setup.yaml for the residuals' tag lever arms (view_server --setup)")
    ap.add_argument('--timeout', type=float, default=600.0, help='give up after this many seconds')
    args = ap.parse_args()

    server = subprocess.Popen([os.path.join(args.bin, 'view_server'), '--log', args.log, '--speed', str(args.speed),
                               '--port', '0', '--perf'] + (['--setup', args.setup] if args.setup else []), stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    url_ready = threading.Event()
    state = {'url': None, 'perf': [], 'played': False}

    def read_server():
        for line in server.stdout:
            line = line.strip()
            if line.startswith('view: http'):
                state['url'] = line.split()[1]
                url_ready.set()
            elif line.startswith('perf: '):
                state['perf'].append(json.loads(line[6:]))
            elif 'to its end' in line:
                state['played'] = True

    threading.Thread(target=read_server, daemon=True).start()
    if not url_ready.wait(30):
        server.kill()
        sys.exit('view_server printed no URL within 30 s')
    tmp = tempfile.mkdtemp(prefix='view_measure_')
    chrome = subprocess.Popen([args.chromium, '--headless', '--no-sandbox', '--disable-gpu', '--no-first-run',
                               '--hide-scrollbars', f'--user-data-dir={tmp}/profile', f'--window-size={args.window}',
                               '--remote-debugging-port=0', state['url'] + '?perf=1'],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                              env=dict(os.environ, TMPDIR=tmp, HOME=tmp))
    start = time.time()
    try:
        # Until the log is played and two more reports have come.
        while time.time() - start < args.timeout:
            time.sleep(0.5)
            rows = state['perf']
            if state['played'] and rows and rows[-1].get('progress') == 1 and \
                    sum(1 for r in rows if r.get('progress') == 1) >= 3:
                break
    finally:
        chrome.terminate()
        server.terminate()
        chrome.wait(10)
        server.wait(10)
        shutil.rmtree(tmp, ignore_errors=True)

    rows = state['perf']
    if len(rows) < 2:
        sys.exit(f'only {len(rows)} reports from the page')
    first = next((r['first_vehicle_frame_ms'] for r in rows if r.get('first_vehicle_frame_ms') is not None), None)
    playing = [(b, a) for a, b in zip(rows, rows[1:]) if b.get('progress') is not None and b['progress'] < 1]
    fps = [b['frames'] / ((b['wall_ms'] - a['wall_ms']) / 1000.0) for b, a in playing if b['wall_ms'] > a['wall_ms']]
    draw = [b['draw_ms'] / b['frames'] for b, _ in playing if b['frames'] > 0]
    print(f'log {args.log} at {args.speed}x, window {args.window}, {len(rows)} reports of the page')
    print(f'first frame with the vehicle: {first} ms after the page was opened')
    if fps:
        print(f'frames per second while playing ({len(fps)} windows of 1 s): min {min(fps):.1f}, '
              f'median {statistics.median(fps):.1f}, mean {statistics.mean(fps):.1f}')
        print(f'draw time per frame: mean {statistics.mean(draw):.2f} ms, max {max(draw):.2f} ms')
    print(f'path points on the page at the end: {rows[-1].get("path_rows")}; data time {rows[-1].get("data_t")} s')


if __name__ == '__main__':
    main()
