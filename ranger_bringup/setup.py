# Installs the ranger_bringup Python package (src/ranger_bringup) through catkin_python_setup().
from catkin_pkg.python_setup import generate_distutils_setup
from setuptools import setup

setup(**generate_distutils_setup(packages=["ranger_bringup"], package_dir={"": "src"}))
