"""ROS 2 launch file for gnss_ins_node, and gnss_ins_ubx_node in front of it.

    ros2 launch launch_scripts/gnss_ins_node.launch.py \
        params_file:=params/ermakf.yaml namespace:=/robot imu_topic:=/sensors/imu \
        publish_tf:=true base_frame:=imu_link

    ros2 launch launch_scripts/gnss_ins_node.launch.py with_ubx_adapter:=true \
        namespace:=/robot imu_topic:=/sensors/imu time_base:=host

Arguments:
- params_file: a parameter file loaded after the manual params/defaults.yaml (which holds
  every parameter at its default): a preset of params/ (they hold only what differs from
  the manual) or a file of your own; default: the manual itself (loaded once).
  namespace, node_name, log_level;
- imu_topic, gnss_topic, fix_topic, velocity_topic, odometry_topic, filtered_fix_topic:
  remappings of the node's relative topics imu, gnss/measurements, gnss/fix,
  gnss/velocity, odometry and fix/filtered (its NavSatFix, named apart from a driver's
  fix in the same namespace);
- the node's own parameters use_sim_time (bool), map_frame, base_frame, odom_frame
  (frame ids), publish_tf (bool), tf_mode (map_to_base_link, map_to_odom or none; see
  docs/tf.md), queue_depth (int) and imu_frame (a frame id). Their default is ''
  meaning "not set": the value then comes from the params file or, when the file has
  none, from the node's default (false, map, base_link, odom, false, map_to_base_link,
  200, '' = learnt). Choice: a parameters dict given after the
  params file overrides it, so only the arguments the user set are passed; a default that
  is always passed would silently override the params file.
- with_ubx_adapter (default false): also start gnss_ins_ubx_node (named ubx_node_name),
  in the same namespace, turning a u-blox receiver's raw GNSS into the gnss_topic that
  gnss_ins_node reads. Its inputs are remapped for ublox_dgnss at the root namespace:
  ubx_rawx_topic (default /ubx_rxm_rawx) and ubx_sfrbx_topic (/ubx_rxm_sfrbx); with
  ublox_gps, set ubx_stream_topic to its raw_data_stream topic. It reads imu_topic for its
  clock check. Its own parameters time_base, leap_seconds, host_latency_s,
  max_imu_gnss_skew_s, ionosphere, frame_id and offset_window_epochs are, like the node
  parameters above, passed only when set; use_sim_time and queue_depth apply to both
  nodes. It gets no params file: the filter's parameters are no parameters of it.
The nodes must be installed as executables gnss_ins_node and gnss_ins_ubx_node of
package adaptive_gnss_ins.
"""

import os

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

PACKAGE_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# The manual: every parameter at its default; the presets are overlays on it.
MANUAL_PARAMS = os.path.join(PACKAGE_ROOT, 'params', 'defaults.yaml')

# The node's own parameters (src/ros/node/params.rs, NODE_PARAMETERS): name -> (type,
# description). The descriptions name the node's defaults.
NODE_PARAMETERS = {
    'use_sim_time': (bool, 'node time follows /clock (node default: false)'),
    'map_frame': (str, 'frame of the odometry pose and TF parent (node default: map)'),
    'base_frame': (str, 'body frame: odometry child and fix frame (node default: base_link)'),
    'odom_frame': (str, 'parent of base_frame in the base controller TF (node default: odom)'),
    'publish_tf': (bool, 'publish the TF of tf_mode on /tf (node default: false)'),
    'tf_mode': (str, 'map_to_base_link, map_to_odom or none (node default: map_to_base_link)'),
    'queue_depth': (int, 'history depth of subscriptions and publishers (node default: 200)'),
    'imu_frame': (str, 'the IMU frame_id; others are dropped (node default: learnt)'),
}

# gnss_ins_ubx_node's own parameters (src/ros/ubx_node/params.rs, UBX_NODE_PARAMETERS)
# but its topic names (remapped below) and those it shares with gnss_ins_node
# (use_sim_time, queue_depth: one launch argument sets both nodes).
UBX_NODE_PARAMETERS = {
    'time_base': (str, 'clock of the GNSS stamps: gnss or host (node default: gnss)'),
    'leap_seconds': (int, 'GPS - UTC (s) while the receiver reports none (node default: 18)'),
    'host_latency_s': (float, 'receiver epoch to host receive stamp, s (node default: 0.035)'),
    'max_imu_gnss_skew_s': (float, 'IMU/GNSS stamp skew warned about, s (node default: 0.01)'),
    'ionosphere': (str, 'iono_free, broadcast or none (node default: iono_free)'),
    'frame_id': (str, 'frame id of the measurements (node default: gnss_antenna)'),
    'offset_window_epochs': (int, 'epochs of the clock check averages (node default: 100)'),
}
SHARED_PARAMETERS = ('use_sim_time', 'queue_depth')

# gnss_ins_ubx_node's inputs: launch argument -> (the node's relative topic name, the
# default it is remapped to). ublox_dgnss at the root namespace publishes /ubx_rxm_rawx
# and /ubx_rxm_sfrbx; absolute defaults keep them found whatever namespace the nodes get.
UBX_TOPIC_REMAPS = {
    'ubx_rawx_topic': ('ubx_rxm_rawx', '/ubx_rxm_rawx'),
    'ubx_sfrbx_topic': ('ubx_rxm_sfrbx', '/ubx_rxm_sfrbx'),
    'ubx_stream_topic': ('ubx_raw', 'ubx_raw'),
}

# Remapped topics: launch argument -> the node's relative topic name.
TOPIC_REMAPS = {
    'imu_topic': 'imu',
    'gnss_topic': 'gnss/measurements',
    'fix_topic': 'gnss/fix',
    'velocity_topic': 'gnss/velocity',
    'odometry_topic': 'odometry',
    'filtered_fix_topic': 'fix/filtered',
}


def _typed(name, kind, text):
    """The launch argument `text` of node parameter `name` as a value of `kind`."""
    if kind is bool:
        if text.lower() in ('true', 'false'):
            return text.lower() == 'true'
        raise ValueError(f'{name} must be true or false, not {text!r}')
    if kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            what = 'an integer' if kind is int else 'a number'
            raise ValueError(f'{name} must be {what}, not {text!r}') from None
    return text


def node_parameter_overrides(values, table=None):
    """The parameters of `table` (default NODE_PARAMETERS) the user set, typed: `values`
    maps each name of the table to its launch argument ('' = not set); names left '' are
    left out, so the params file (or the node's default) decides them."""
    table = NODE_PARAMETERS if table is None else table
    return {
        name: _typed(name, kind, values[name])
        for name, (kind, _) in table.items()
        if values[name] != ''
    }


def _ubx_node(value):
    """gnss_ins_ubx_node in front of gnss_ins_node (`value` reads a launch argument)."""
    table = dict(UBX_NODE_PARAMETERS, **{n: NODE_PARAMETERS[n] for n in SHARED_PARAMETERS})
    overrides = node_parameter_overrides({name: value(name) for name in table}, table)
    remappings = [(topic, value(argument)) for argument, (topic, _) in UBX_TOPIC_REMAPS.items()]
    remappings += [('imu', value('imu_topic')), ('gnss/measurements', value('gnss_topic'))]
    return Node(
        package='adaptive_gnss_ins',
        executable='gnss_ins_ubx_node',
        name=value('ubx_node_name'),
        namespace=value('namespace'),
        parameters=[overrides] if overrides else [],
        remappings=remappings,
        arguments=['--ros-args', '--log-level', value('log_level')],
        output='screen',
    )


def _launch_node(context):
    def value(name):
        return LaunchConfiguration(name).perform(context)

    # rcl reads the files in order and a later value wins: the manual, then the preset,
    # then the overrides (launch_ros writes them to a temporary file passed last).
    parameters = [MANUAL_PARAMS]
    params_file = value('params_file')
    if params_file and os.path.abspath(params_file) != MANUAL_PARAMS:
        parameters.append(params_file)
    overrides = node_parameter_overrides({name: value(name) for name in NODE_PARAMETERS})
    if overrides:
        parameters.append(overrides)
    nodes = [Node(
        package='adaptive_gnss_ins',
        executable='gnss_ins_node',
        name=value('node_name'),
        namespace=value('namespace'),
        parameters=parameters,
        remappings=[(topic, value(argument)) for argument, topic in TOPIC_REMAPS.items()],
        arguments=['--ros-args', '--log-level', value('log_level')],
        output='screen',
    )]
    if _typed('with_ubx_adapter', bool, value('with_ubx_adapter')):
        nodes.append(_ubx_node(value))
    return nodes


def generate_launch_description():
    arguments = [
        DeclareLaunchArgument('params_file', default_value=MANUAL_PARAMS,
                              description='parameter file loaded after params/defaults.yaml (a '
                                          'preset of params/ or your own)'),
        DeclareLaunchArgument('namespace', default_value='',
                              description='namespace of the node and its topics'),
        DeclareLaunchArgument('node_name', default_value='gnss_ins_node',
                              description='node name (the params file key must match or be /**)'),
        DeclareLaunchArgument('log_level', default_value='info'),
        DeclareLaunchArgument('with_ubx_adapter', default_value='false',
                              description='also start gnss_ins_ubx_node (u-blox raw GNSS '
                                          '-> gnss_topic)'),
        DeclareLaunchArgument('ubx_node_name', default_value='gnss_ins_ubx_node',
                              description='name of gnss_ins_ubx_node'),
    ]
    arguments += [
        DeclareLaunchArgument(argument, default_value=default,
                              description=f'topic gnss_ins_ubx_node\'s {topic} is remapped to')
        for argument, (topic, default) in UBX_TOPIC_REMAPS.items()
    ]
    arguments += [
        DeclareLaunchArgument(argument, default_value=topic,
                              description=f'topic the node\'s {topic} is remapped to')
        for argument, topic in TOPIC_REMAPS.items()
    ]
    arguments += [
        DeclareLaunchArgument(name, default_value='',
                              description=f'{description}; \'\' = not set (params file)')
        for name, (_, description) in list(NODE_PARAMETERS.items())
        + list(UBX_NODE_PARAMETERS.items())
    ]
    return LaunchDescription(arguments + [OpaqueFunction(function=_launch_node)])
