"""./meshnav import rosbag|miluv|csv ... (run as `python3 -m meshnav_import` with tools/ on the path)."""

import argparse
import sys

from . import dataset_writer as dw
from . import csv_importer, miluv_importer, rosbag_importer


def main(argv=None):
    p = argparse.ArgumentParser(prog="meshnav import", description=(
        "Real recordings into a meshnav dataset folder (docs/formats.md); time stamps stay as recorded. "
        "See docs/real_data.md."))
    sub = p.add_subparsers(dest="kind", required=True)
    rosbag_importer.add_arguments(sub.add_parser(
        "rosbag", help="ROS 1 bag (IMU, RTLS UWB ranges, anchor list, truth pose)",
        description=rosbag_importer.__doc__, formatter_class=argparse.RawDescriptionHelpFormatter))
    miluv_importer.add_arguments(sub.add_parser(
        "miluv", help="one robot of a MILUV experiment folder",
        description=miluv_importer.__doc__, formatter_class=argparse.RawDescriptionHelpFormatter))
    csv_importer.add_arguments(sub.add_parser(
        "csv", help="your own CSV files, described by a mapping file (--map FILE)",
        description=csv_importer.__doc__, formatter_class=argparse.RawDescriptionHelpFormatter))
    args = p.parse_args(argv)
    module = {"rosbag": rosbag_importer, "miluv": miluv_importer, "csv": csv_importer}[args.kind]
    try:
        return module.run(args)
    except (ValueError, OSError) as ex:
        dw.log(f"error: {ex}")
        return 1


if __name__ == "__main__":
    sys.exit(main())
