from setuptools import setup

package_name = "ranger_base"

setup(
    name=package_name,
    version="0.1.0",
    packages=[package_name],
    data_files=[
        ("share/ament_index/resource_index/packages", ["resource/" + package_name]),
        ("share/" + package_name, ["package.xml"]),
    ],
    install_requires=["setuptools"],
    zip_safe=True,
    maintainer="ranger_ros maintainers",
    maintainer_email="maintainers@ranger-ros.invalid",
    description="ranger_base_node for ROS 2 (rclpy over the ranger_can binding)",
    license="BSD-3-Clause",
    tests_require=["pytest"],
    entry_points={"console_scripts": [
        "ranger_base_node = ranger_base.node:main",
        "measure_performance = ranger_base.measure_performance:main"]},
)
