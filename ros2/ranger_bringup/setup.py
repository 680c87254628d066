import glob

from setuptools import setup

package_name = "ranger_bringup"

setup(
    name=package_name,
    version="0.1.0",
    packages=[package_name],
    data_files=[
        ("share/ament_index/resource_index/packages", ["resource/" + package_name]),
        ("share/" + package_name, ["package.xml"]),
        ("share/" + package_name + "/launch", glob.glob("launch/*.launch.py")),
    ],
    install_requires=["setuptools"],
    zip_safe=True,
    maintainer="ranger_ros maintainers",
    maintainer_email="maintainers@ranger-ros.invalid",
    description="Launch files and keyboard teleop for the RANGER on ROS 2",
    license="BSD-3-Clause",
    entry_points={"console_scripts": [
        "ranger_teleop_keyboard = ranger_bringup.teleop_keyboard:main"]},
)
