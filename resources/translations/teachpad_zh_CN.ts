<?xml version="1.0" encoding="utf-8"?>
<!DOCTYPE TS>
<TS version="2.1" language="zh_CN">
<context>
    <name></name>
    <message>
        <location filename="../../ui/points_model.py" line="112"/>
        <source>none</source>
        <extracomment>Columns of the table: the point&apos;s fields in CSV order, with the sync state before the note. Custom roles. Text the tool cell accepts for &quot;no tool frame&quot; besides 200.</extracomment>
        <translation type="unfinished">无</translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="113"/>
        <source>tool {n}</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="358"/>
        <source>ID</source>
        <extracomment>An edit refused (bad value, duplicate id ...): the message for the status line. A command changed ``target``&apos;s list (after the change).</extracomment>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="358"/>
        <source>Name</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="358"/>
        <source>Tool</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="358"/>
        <source>Sync</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="358"/>
        <source>Note</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="361"/>
        <source>Temp point id on the controller</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="362"/>
        <source>Tool frame (200 = none)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="363"/>
        <source>Whether the controller holds this point</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="364"/>
        <source>mm, base frame</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="365"/>
        <source>degrees</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="366"/>
        <source>External axis (recorded only: the controller does not store it)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="445"/>
        <source>Upload failed: {reason}</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="445"/>
        <source>no reason given</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="447"/>
        <source>Not known whether the controller holds this point (it restarted or the link was lost): upload it before moving to it</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="449"/>
        <source>The controller holds this point with these values</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="450"/>
        <source>Changed on the host (or new) since the last upload</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="455"/>
        <source>Tool frame {value}</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="486"/>
        <source>{point}, {column}: refused, {reason}</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="502"/>
        <source>Edit {point} {column}</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="534"/>
        <source>Add {point}</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="550"/>
        <source>Duplicate {point}</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="551"/>
        <source>Duplicate {n} points</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="568"/>
        <source>Delete {point}</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="569"/>
        <source>Delete {n} points</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="584"/>
        <source>Move up</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="584"/>
        <source>Move down</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="600"/>
        <source>Teach {point}</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/points_model.py" line="607"/>
        <source>Import {n} points</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>ConnectionDialog</name>
    <message>
        <location filename="../../ui/connection_dialog.py" line="115"/>
        <source>Connect to controller</source>
        <translation>连接控制器</translation>
    </message>
    <message>
        <location filename="../../ui/connection_dialog.py" line="116"/>
        <source>Transport:</source>
        <translation>通信方式：</translation>
    </message>
    <message>
        <location filename="../../ui/connection_dialog.py" line="117"/>
        <source>Modbus TCP</source>
        <translation>Modbus TCP</translation>
    </message>
    <message>
        <location filename="../../ui/connection_dialog.py" line="118"/>
        <source>Modbus RTU (serial)</source>
        <translation>Modbus RTU（串口）</translation>
    </message>
    <message>
        <location filename="../../ui/connection_dialog.py" line="119"/>
        <source>Host:</source>
        <translation>主机：</translation>
    </message>
    <message>
        <location filename="../../ui/connection_dialog.py" line="120"/>
        <source>Port:</source>
        <translation>端口：</translation>
    </message>
    <message>
        <location filename="../../ui/connection_dialog.py" line="121"/>
        <source>Serial port:</source>
        <translation>串口：</translation>
    </message>
    <message>
        <location filename="../../ui/connection_dialog.py" line="122"/>
        <source>Baud rate:</source>
        <translation>波特率：</translation>
    </message>
    <message>
        <location filename="../../ui/connection_dialog.py" line="123"/>
        <source>Parity:</source>
        <translation>校验位：</translation>
    </message>
    <message>
        <location filename="../../ui/connection_dialog.py" line="124"/>
        <source>none</source>
        <translation>无</translation>
    </message>
    <message>
        <location filename="../../ui/connection_dialog.py" line="124"/>
        <source>even</source>
        <translation>偶校验</translation>
    </message>
    <message>
        <location filename="../../ui/connection_dialog.py" line="124"/>
        <source>odd</source>
        <translation>奇校验</translation>
    </message>
    <message>
        <location filename="../../ui/connection_dialog.py" line="126"/>
        <source>Stop bits:</source>
        <translation>停止位：</translation>
    </message>
    <message>
        <location filename="../../ui/connection_dialog.py" line="127"/>
        <source>Unit id:</source>
        <translation>从站地址：</translation>
    </message>
    <message>
        <location filename="../../ui/connection_dialog.py" line="128"/>
        <source>Float word order:</source>
        <translation>浮点数字序：</translation>
    </message>
    <message>
        <location filename="../../ui/connection_dialog.py" line="129"/>
        <source>Low word first (CDAB, default)</source>
        <translation>低字在前（CDAB，默认）</translation>
    </message>
    <message>
        <location filename="../../ui/connection_dialog.py" line="130"/>
        <source>High word first (ABCD)</source>
        <translation>高字在前（ABCD）</translation>
    </message>
    <message>
        <location filename="../../ui/connection_dialog.py" line="131"/>
        <source>Timeout:</source>
        <translation>超时：</translation>
    </message>
    <message>
        <location filename="../../ui/connection_dialog.py" line="132"/>
        <source>Monitor only (never write to the controller)</source>
        <translation>仅监视（从不写入控制器）</translation>
    </message>
    <message>
        <location filename="../../ui/connection_dialog.py" line="180"/>
        <source>a serial port is needed for RTU</source>
        <translation>RTU 方式需要指定串口</translation>
    </message>
</context>
<context>
    <name>ControlBar</name>
    <message>
        <location filename="../../ui/control_bar.py" line="95"/>
        <source>STOP</source>
        <translation>停止</translation>
    </message>
    <message>
        <location filename="../../ui/control_bar.py" line="96"/>
        <source>Stop all motion (Esc)</source>
        <translation>停止所有运动（Esc）</translation>
    </message>
    <message>
        <location filename="../../ui/control_bar.py" line="97"/>
        <source>Pause</source>
        <translation>暂停</translation>
    </message>
    <message>
        <location filename="../../ui/control_bar.py" line="98"/>
        <source>Pause the current move or program</source>
        <translation>暂停当前运动或程序</translation>
    </message>
    <message>
        <location filename="../../ui/control_bar.py" line="99"/>
        <source>Resume</source>
        <translation>继续</translation>
    </message>
    <message>
        <location filename="../../ui/control_bar.py" line="100"/>
        <source>Resume the paused move or program</source>
        <translation>继续已暂停的运动或程序</translation>
    </message>
    <message>
        <location filename="../../ui/control_bar.py" line="101"/>
        <source>The controller&apos;s work mode (register 560)</source>
        <translation>控制器工作模式（寄存器 560）</translation>
    </message>
    <message>
        <location filename="../../ui/control_bar.py" line="102"/>
        <source>Manual</source>
        <translation>手动</translation>
    </message>
    <message>
        <location filename="../../ui/control_bar.py" line="103"/>
        <source>Switch the controller to manual mode</source>
        <translation>将控制器切换到手动模式</translation>
    </message>
    <message>
        <location filename="../../ui/control_bar.py" line="104"/>
        <source>Auto</source>
        <translation>自动</translation>
    </message>
    <message>
        <location filename="../../ui/control_bar.py" line="105"/>
        <source>Switch the controller to auto mode (needed for Modbus motion)</source>
        <translation>将控制器切换到自动模式（Modbus 运动需要自动模式）</translation>
    </message>
    <message>
        <location filename="../../ui/control_bar.py" line="138"/>
        <source>Mode:
{mode}</source>
        <translation>模式：
{mode}</translation>
    </message>
</context>
<context>
    <name>EventLogModel</name>
    <message>
        <location filename="../../ui/event_log.py" line="92"/>
        <source>Time</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/event_log.py" line="93"/>
        <source>Level</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/event_log.py" line="94"/>
        <source>Source</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/event_log.py" line="95"/>
        <source>Message</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/event_log.py" line="98"/>
        <source>Info</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/event_log.py" line="99"/>
        <source>Warning</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/event_log.py" line="100"/>
        <source>Error</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>EventLogPanel</name>
    <message>
        <location filename="../../ui/event_log.py" line="263"/>
        <source>Show:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/event_log.py" line="264"/>
        <source>All events</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/event_log.py" line="265"/>
        <source>Warnings and errors</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/event_log.py" line="266"/>
        <source>Errors only</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/event_log.py" line="267"/>
        <source>Clear</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/event_log.py" line="268"/>
        <source>Export…</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/event_log.py" line="299"/>
        <source>alarm</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/event_log.py" line="306"/>
        <source>Alarm raised: {name}</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/event_log.py" line="308"/>
        <source>Alarm cleared: {name}</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/event_log.py" line="314"/>
        <source>bit {n}</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/event_log.py" line="318"/>
        <source>command</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/event_log.py" line="337"/>
        <source>link</source>
        <translation type="unfinished">通信</translation>
    </message>
    <message>
        <location filename="../../ui/event_log.py" line="364"/>
        <location filename="../../ui/event_log.py" line="375"/>
        <source>Export event log</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/event_log.py" line="366"/>
        <source>Text files (*.txt *.log);;All files (*)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/event_log.py" line="376"/>
        <source>Could not write {path}: {error}</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>JogPanel</name>
    <message>
        <location filename="../../ui/jog_panel.py" line="214"/>
        <source>Frame</source>
        <translation>坐标系</translation>
    </message>
    <message>
        <location filename="../../ui/jog_panel.py" line="216"/>
        <source>Base frame</source>
        <translation>基坐标系</translation>
    </message>
    <message>
        <location filename="../../ui/jog_panel.py" line="217"/>
        <source>User frame</source>
        <translation>用户坐标系</translation>
    </message>
    <message>
        <location filename="../../ui/jog_panel.py" line="218"/>
        <source>Tool frame</source>
        <translation>工具坐标系</translation>
    </message>
    <message>
        <location filename="../../ui/jog_panel.py" line="219"/>
        <source>Joint frame</source>
        <translation>关节坐标系</translation>
    </message>
    <message>
        <location filename="../../ui/jog_panel.py" line="223"/>
        <source>User no.:</source>
        <translation>用户坐标号：</translation>
    </message>
    <message>
        <location filename="../../ui/jog_panel.py" line="224"/>
        <source>Tool no.:</source>
        <translation>工具号：</translation>
    </message>
    <message>
        <location filename="../../ui/jog_panel.py" line="225"/>
        <source>Jog</source>
        <translation>点动</translation>
    </message>
    <message>
        <location filename="../../ui/jog_panel.py" line="226"/>
        <source>External axes</source>
        <translation>外部轴</translation>
    </message>
    <message>
        <location filename="../../ui/jog_panel.py" line="227"/>
        <source>HOLD TO MOVE — release to stop</source>
        <translation>按住运动 — 松开即停</translation>
    </message>
    <message>
        <location filename="../../ui/jog_panel.py" line="228"/>
        <source>Speed:</source>
        <translation>速度：</translation>
    </message>
    <message>
        <location filename="../../ui/jog_panel.py" line="233"/>
        <source>Keyboard: click this panel, then hold {plus} (+) or {minus} (−) for axes 1–6; releasing the key stops.</source>
        <translation>键盘：先单击本面板，再按住 {plus}（+）或 {minus}（−）点动第 1–6 轴；松开按键即停止。</translation>
    </message>
    <message>
        <location filename="../../ui/jog_panel.py" line="358"/>
        <source>°</source>
        <translation>°</translation>
    </message>
    <message>
        <location filename="../../ui/jog_panel.py" line="358"/>
        <source>mm</source>
        <translation>mm</translation>
    </message>
    <message>
        <location filename="../../ui/jog_panel.py" line="359"/>
        <source>Hold: {axis} − ({unit})</source>
        <translation>按住：{axis} −（{unit}）</translation>
    </message>
    <message>
        <location filename="../../ui/jog_panel.py" line="361"/>
        <source>Hold: {axis} + ({unit})</source>
        <translation>按住：{axis} +（{unit}）</translation>
    </message>
    <message>
        <location filename="../../ui/jog_panel.py" line="372"/>
        <source>{ratio} %</source>
        <translation>{ratio} %</translation>
    </message>
</context>
<context>
    <name>MainWindow</name>
    <message>
        <location filename="../../ui/main_window.py" line="225"/>
        <source>Jog</source>
        <translation>点动</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="226"/>
        <source>Step</source>
        <translation>增量运动</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="227"/>
        <source>Program</source>
        <translation>程序</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="228"/>
        <source>Position</source>
        <translation>位置</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="229"/>
        <source>Status</source>
        <translation>状态</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="230"/>
        <source>Event log</source>
        <translation>事件日志</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="231"/>
        <source>Modbus traffic</source>
        <translation>Modbus 报文</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="232"/>
        <source>&amp;File</source>
        <translation>文件(&amp;F)</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="233"/>
        <source>&amp;Motion</source>
        <translation>运动(&amp;M)</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="234"/>
        <source>&amp;View</source>
        <translation>视图(&amp;V)</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="235"/>
        <source>&amp;Language</source>
        <translation>语言(&amp;L)</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="236"/>
        <source>&amp;Help</source>
        <translation>帮助(&amp;H)</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="237"/>
        <location filename="../../ui/main_window.py" line="238"/>
        <source>Toolbar</source>
        <translation>工具栏</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="239"/>
        <source>&amp;Connect…</source>
        <translation>连接(&amp;C)…</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="240"/>
        <source>Connect to a controller (Ctrl+K)</source>
        <translation>连接控制器（Ctrl+K）</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="241"/>
        <source>&amp;Disconnect</source>
        <translation>断开(&amp;D)</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="242"/>
        <source>&amp;Quit</source>
        <translation>退出(&amp;Q)</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="243"/>
        <source>&amp;Stop</source>
        <translation>停止(&amp;S)</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="244"/>
        <source>Stop all motion (Esc)</source>
        <translation>停止所有运动（Esc）</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="245"/>
        <source>&amp;Pause</source>
        <translation>暂停(&amp;P)</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="246"/>
        <source>Pause the current move or program (F6)</source>
        <translation>暂停当前运动或程序（F6）</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="247"/>
        <source>&amp;Resume</source>
        <translation>继续(&amp;R)</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="248"/>
        <source>Resume the paused move or program (F7)</source>
        <translation>继续已暂停的运动或程序（F7）</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="249"/>
        <source>&amp;About TeachPad</source>
        <translation>关于 TeachPad(&amp;A)</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="250"/>
        <location filename="../../ui/main_window.py" line="315"/>
        <source>MONITOR ONLY</source>
        <translation>仅监视</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="252"/>
        <source>stop</source>
        <translation>停止</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="253"/>
        <source>pause</source>
        <translation>暂停</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="254"/>
        <source>resume</source>
        <translation>继续</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="255"/>
        <source>jog</source>
        <translation>点动</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="256"/>
        <source>jog release</source>
        <translation>点动松开</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="257"/>
        <source>jog speed</source>
        <translation>点动速度</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="258"/>
        <source>incremental move</source>
        <translation>增量运动</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="259"/>
        <source>work mode</source>
        <translation>工作模式</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="260"/>
        <source>go to zero</source>
        <translation>回零</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="261"/>
        <source>run program</source>
        <translation>运行程序</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="262"/>
        <source>create temp point</source>
        <translation>创建临时点</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="263"/>
        <source>move to temp point</source>
        <translation>运动到临时点</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="264"/>
        <source>upload temp points</source>
        <translation>上传临时点</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="265"/>
        <source>teach disable</source>
        <translation>关闭示教</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="266"/>
        <source>monitor</source>
        <translation>监视</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="267"/>
        <source>connect</source>
        <translation>连接</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="268"/>
        <source>disconnect</source>
        <translation>断开</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="269"/>
        <source>shutdown</source>
        <translation>关闭</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="289"/>
        <source>TeachPad</source>
        <translation>TeachPad 示教器</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="312"/>
        <source>link down</source>
        <translation>通信中断</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="331"/>
        <source>Monitor only: motion controls are disabled</source>
        <translation>仅监视：运动控制已禁用</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="333"/>
        <source>Not connected: motion controls are disabled</source>
        <translation>未连接：运动控制已禁用</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="343"/>
        <source>RTT {ms} ms</source>
        <translation>往返 {ms} ms</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="357"/>
        <source>Reconnected to the controller: jog stopped and teach mode switched off</source>
        <translation>已重新连接控制器：点动已停止，示教模式已关闭</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="358"/>
        <source>link</source>
        <translation>通信</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="416"/>
        <source>About TeachPad</source>
        <translation>关于 TeachPad</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="417"/>
        <source>&lt;b&gt;TeachPad {version}&lt;/b&gt;&lt;br&gt;Desktop teach pendant for Bochuang robot controllers (Modbus TCP / RTU).&lt;br&gt;&lt;br&gt;Esc stops all motion. Jog buttons and keys move only while held.</source>
        <translation>&lt;b&gt;TeachPad {version}&lt;/b&gt;&lt;br&gt;博创机器人控制器桌面示教器（Modbus TCP / RTU）。&lt;br&gt;&lt;br&gt;按 Esc 停止所有运动。点动按钮和按键仅在按住时运动。</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="425"/>
        <source>language</source>
        <translation>语言</translation>
    </message>
    <message>
        <location filename="../../ui/main_window.py" line="426"/>
        <source>No translation file for {code}</source>
        <translation>没有 {code} 的翻译文件</translation>
    </message>
</context>
<context>
    <name>MonitorPanel</name>
    <message>
        <location filename="../../ui/monitor_panel.py" line="225"/>
        <source>mm</source>
        <translation type="unfinished">mm</translation>
    </message>
    <message>
        <location filename="../../ui/monitor_panel.py" line="225"/>
        <source>°</source>
        <translation type="unfinished">°</translation>
    </message>
    <message>
        <location filename="../../ui/monitor_panel.py" line="226"/>
        <source>TCP position (base frame)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/monitor_panel.py" line="227"/>
        <source>Joints and external axes</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/monitor_panel.py" line="234"/>
        <source>{n} s</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/monitor_panel.py" line="235"/>
        <source>Time span of the position plots</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/monitor_panel.py" line="236"/>
        <source>Window:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/monitor_panel.py" line="237"/>
        <source>Pause plots</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/monitor_panel.py" line="238"/>
        <source>Freeze the plots; samples keep being recorded</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/monitor_panel.py" line="239"/>
        <source>Clear trace</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/monitor_panel.py" line="240"/>
        <source>Erase the X–Y path trace</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/monitor_panel.py" line="241"/>
        <source>position</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/monitor_panel.py" line="242"/>
        <source>orientation</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/monitor_panel.py" line="243"/>
        <source>time</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/monitor_panel.py" line="243"/>
        <source>s</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/monitor_panel.py" line="244"/>
        <source>TCP path, top view (X–Y)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/monitor_panel.py" line="403"/>
        <source>Plots: last {n} s</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/monitor_panel.py" line="405"/>
        <source>paused</source>
        <translation type="unfinished">已暂停</translation>
    </message>
</context>
<context>
    <name>Panels</name>
    <message>
        <location filename="../../ui/widgets_common.py" line="233"/>
        <source>connected</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/widgets_common.py" line="234"/>
        <source>connecting</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/widgets_common.py" line="235"/>
        <source>reconnecting</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/widgets_common.py" line="236"/>
        <source>disconnected</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/widgets_common.py" line="237"/>
        <source>stopped</source>
        <translation type="unfinished">已停止</translation>
    </message>
    <message>
        <location filename="../../ui/widgets_common.py" line="238"/>
        <source>link down</source>
        <translation type="unfinished">通信中断</translation>
    </message>
    <message>
        <location filename="../../ui/widgets_common.py" line="239"/>
        <location filename="../../ui/widgets_common.py" line="240"/>
        <source>link lost</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/widgets_common.py" line="241"/>
        <source>error</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/widgets_common.py" line="242"/>
        <location filename="../../ui/widgets_common.py" line="273"/>
        <source>failed</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/widgets_common.py" line="264"/>
        <source>command</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/widgets_common.py" line="272"/>
        <source>done</source>
        <translation type="unfinished">完成</translation>
    </message>
    <message>
        <location filename="../../ui/widgets_common.py" line="281"/>
        <source>{command}: {status}</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>Plan</name>
    <message>
        <location filename="../../app/plan.py" line="74"/>
        <source>line</source>
        <extracomment>Time added per segment to length / speed: command round trip, acceleration, settling (s). Editable fields of a segment, in table column order.</extracomment>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../app/plan.py" line="75"/>
        <source>arc</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>PlanListModel</name>
    <message>
        <location filename="../../ui/plan_model.py" line="190"/>
        <source>Plan</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="190"/>
        <source>Loops</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="190"/>
        <source>Segments</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="238"/>
        <source>endless</source>
        <translation type="unfinished">无限循环</translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="242"/>
        <source>How many times the plan runs (0 = until stopped)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="267"/>
        <source>Plan: refused, {reason}</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="273"/>
        <source>plan</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="277"/>
        <source>Add plan {name}</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="284"/>
        <source>Duplicate plan {name}</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="289"/>
        <source>Delete plan {name}</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="300"/>
        <source>Rename plan {old} to {new}</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="309"/>
        <source>Set loops of {name} to {n}</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>Points</name>
    <message>
        <location filename="../../app/points.py" line="131"/>
        <source>unknown</source>
        <extracomment>The editable fields of a point, in table / CSV column order. Fields the controller stores: editing one of them makes the point &quot;changed on host&quot;.</extracomment>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../app/points.py" line="132"/>
        <source>on controller</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../app/points.py" line="133"/>
        <source>changed on host</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../app/points.py" line="134"/>
        <source>upload failed</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>ProgramPanel</name>
    <message>
        <location filename="../../ui/program_panel.py" line="102"/>
        <source>Program</source>
        <translation>程序</translation>
    </message>
    <message>
        <location filename="../../ui/program_panel.py" line="103"/>
        <source>Program no.:</source>
        <translation>程序号：</translation>
    </message>
    <message>
        <location filename="../../ui/program_panel.py" line="103"/>
        <source>Run mode:</source>
        <translation>运行方式：</translation>
    </message>
    <message>
        <location filename="../../ui/program_panel.py" line="103"/>
        <source>Cycles:</source>
        <translation>循环次数：</translation>
    </message>
    <message>
        <location filename="../../ui/program_panel.py" line="103"/>
        <source>Speed:</source>
        <translation>速度：</translation>
    </message>
    <message>
        <location filename="../../ui/program_panel.py" line="108"/>
        <source>endless</source>
        <translation>无限循环</translation>
    </message>
    <message>
        <location filename="../../ui/program_panel.py" line="109"/>
        <source>Number of cycles in cycle mode; 0 runs until stopped</source>
        <translation>循环模式下的循环次数；0 表示一直运行直到停止</translation>
    </message>
    <message>
        <location filename="../../ui/program_panel.py" line="110"/>
        <source>Run program</source>
        <translation>运行程序</translation>
    </message>
    <message>
        <location filename="../../ui/program_panel.py" line="111"/>
        <location filename="../../ui/program_panel.py" line="113"/>
        <source>Go to zero</source>
        <translation>回零</translation>
    </message>
    <message>
        <location filename="../../ui/program_panel.py" line="112"/>
        <source>All axes</source>
        <translation>所有轴</translation>
    </message>
    <message>
        <location filename="../../ui/program_panel.py" line="146"/>
        <source>Run program {id} ({mode}) at {speed} %? The arm will move.</source>
        <translation>以 {speed} % 速度运行程序 {id}（{mode}）？机械臂将会运动。</translation>
    </message>
    <message>
        <location filename="../../ui/program_panel.py" line="148"/>
        <source>Confirm program run</source>
        <translation>确认运行程序</translation>
    </message>
    <message>
        <location filename="../../ui/program_panel.py" line="154"/>
        <source>all axes</source>
        <translation>所有轴</translation>
    </message>
    <message>
        <location filename="../../ui/program_panel.py" line="155"/>
        <source>Move {which} to zero? The arm will move.</source>
        <translation>将 {which} 回零？机械臂将会运动。</translation>
    </message>
    <message>
        <location filename="../../ui/program_panel.py" line="156"/>
        <source>Confirm go to zero</source>
        <translation>确认回零</translation>
    </message>
</context>
<context>
    <name>Protocol</name>
    <message>
        <location filename="../../app/protocol/enums.py" line="39"/>
        <source>run program</source>
        <translation>运行程序</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="40"/>
        <source>incremental move (joint)</source>
        <translation>增量运动（关节）</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="41"/>
        <source>incremental move (base)</source>
        <translation>增量运动（基坐标）</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="42"/>
        <source>move to temp point</source>
        <translation>运动到临时点</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="43"/>
        <source>teach enable</source>
        <translation>示教使能</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="44"/>
        <source>teach disable</source>
        <translation>示教关闭</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="45"/>
        <source>create temp point</source>
        <translation>创建临时点</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="65"/>
        <source>manual</source>
        <translation>手动</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="66"/>
        <source>auto</source>
        <translation>自动</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="67"/>
        <source>Modbus teach</source>
        <translation>Modbus 示教</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="80"/>
        <source>stopped</source>
        <translation>已停止</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="81"/>
        <source>running</source>
        <translation>运行中</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="82"/>
        <source>paused</source>
        <translation>已暂停</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="95"/>
        <source>single step</source>
        <translation>单步</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="96"/>
        <source>single run</source>
        <translation>单次运行</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="97"/>
        <source>cycle</source>
        <translation>循环</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="111"/>
        <source>base</source>
        <translation>基坐标系</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="112"/>
        <source>user</source>
        <translation>用户坐标系</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="113"/>
        <source>tool</source>
        <translation>工具坐标系</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="114"/>
        <source>joint</source>
        <translation>关节坐标系</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="133"/>
        <location filename="../../app/protocol/enums.py" line="219"/>
        <location filename="../../app/protocol/enums.py" line="241"/>
        <source>emergency stop</source>
        <translation>急停</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="134"/>
        <location filename="../../app/protocol/enums.py" line="220"/>
        <location filename="../../app/protocol/enums.py" line="242"/>
        <source>servo alarm</source>
        <translation>伺服报警</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="135"/>
        <location filename="../../app/protocol/enums.py" line="221"/>
        <location filename="../../app/protocol/enums.py" line="243"/>
        <source>brake alarm</source>
        <translation>抱闸报警</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="136"/>
        <location filename="../../app/protocol/enums.py" line="245"/>
        <source>algorithm alarm</source>
        <translation>算法报警</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="137"/>
        <source>encoder angle alarm</source>
        <translation>编码器角度报警</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="216"/>
        <location filename="../../app/protocol/enums.py" line="233"/>
        <location filename="../../app/protocol/enums.py" line="238"/>
        <source>initial</source>
        <translation>初始</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="217"/>
        <source>done</source>
        <translation>完成</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="218"/>
        <location filename="../../app/protocol/enums.py" line="240"/>
        <source>work mode error</source>
        <translation>工作模式错误</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="222"/>
        <location filename="../../app/protocol/enums.py" line="244"/>
        <source>bus servo initialisation error</source>
        <translation>总线伺服初始化错误</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="223"/>
        <source>moving</source>
        <translation>运动中</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="224"/>
        <source>data length error</source>
        <translation>数据长度错误</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="225"/>
        <source>encoder angle read error</source>
        <translation>编码器角度读取错误</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="226"/>
        <source>encoder angle update error</source>
        <translation>编码器角度更新错误</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="227"/>
        <source>calculation error</source>
        <translation>计算错误</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="228"/>
        <source>algorithm error while moving</source>
        <translation>运动中算法错误</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="229"/>
        <source>motion timeout</source>
        <translation>运动超时</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="230"/>
        <source>bad end point id</source>
        <translation>终点编号错误</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="234"/>
        <location filename="../../app/protocol/enums.py" line="239"/>
        <source>success</source>
        <translation>成功</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="235"/>
        <source>bad point id</source>
        <translation>点编号错误</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="246"/>
        <source>teach speed ratio not zero: enable/disable refused</source>
        <translation>示教速度比例不为零：拒绝使能/关闭</translation>
    </message>
    <message>
        <location filename="../../app/protocol/enums.py" line="259"/>
        <source>unknown status {code}</source>
        <translation>未知状态 {code}</translation>
    </message>
</context>
<context>
    <name>Runner</name>
    <message>
        <location filename="../../app/runner.py" line="80"/>
        <source>ready</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../app/runner.py" line="81"/>
        <source>running</source>
        <translation type="unfinished">运行中</translation>
    </message>
    <message>
        <location filename="../../app/runner.py" line="82"/>
        <source>finished</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../app/runner.py" line="83"/>
        <source>stopped</source>
        <translation type="unfinished">已停止</translation>
    </message>
    <message>
        <location filename="../../app/runner.py" line="84"/>
        <source>failed</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>SegmentTableModel</name>
    <message>
        <location filename="../../ui/plan_model.py" line="378"/>
        <source>Type</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="378"/>
        <source>Middle point</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="378"/>
        <source>End point</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="378"/>
        <source>Speed (mm/s)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="379"/>
        <source>Orientation</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="379"/>
        <source>Ignore middle</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="379"/>
        <source>Tool</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="379"/>
        <source>Length (mm)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="380"/>
        <source>Time (s)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="466"/>
        <source>Middle point of an arc (GV200)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="467"/>
        <source>End point (GV201)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="468"/>
        <source>Orientation kept constant or changing along the move (GV202)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="469"/>
        <source>Ignore the arc&apos;s middle point orientation (GV203)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="470"/>
        <source>Tool frame of the move (GV245)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="471"/>
        <source>Estimated path length</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="472"/>
        <source>Estimated time: length / speed plus a fixed overhead per segment</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="568"/>
        <source>Segment {n}: no problems found</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="573"/>
        <source>Point P{id} does not exist</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="607"/>
        <source>Segment {n}, {column}: refused, {reason}</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="628"/>
        <source>Edit segment {n} {column}</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="639"/>
        <source>Add {kind} segment</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="671"/>
        <source>Add {n} segments</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="678"/>
        <source>Delete segment {n}</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="679"/>
        <source>Delete {n} segments</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="695"/>
        <source>Move segment up</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/plan_model.py" line="695"/>
        <source>Move segment down</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>StatusPanel</name>
    <message>
        <location filename="../../ui/status_panel.py" line="179"/>
        <source>Link</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/status_panel.py" line="180"/>
        <source>Controller</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/status_panel.py" line="181"/>
        <source>Alarms</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/status_panel.py" line="183"/>
        <source>State:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/status_panel.py" line="184"/>
        <source>RTT:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/status_panel.py" line="185"/>
        <source>Mode:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/status_panel.py" line="186"/>
        <source>Program:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/status_panel.py" line="187"/>
        <source>Last command:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/status_panel.py" line="188"/>
        <source>Clock:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/status_panel.py" line="189"/>
        <source>Drift:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/status_panel.py" line="190"/>
        <source>Round-trip time of the last poll</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/status_panel.py" line="194"/>
        <source>Register 562 bit {bit}</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/status_panel.py" line="195"/>
        <source>Register 562 bits with no documented meaning</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/status_panel.py" line="198"/>
        <source>disconnected</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/status_panel.py" line="206"/>
        <source>none yet</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/status_panel.py" line="282"/>
        <source>other bits: {bits}</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/status_panel.py" line="284"/>
        <source>other bits</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/status_panel.py" line="293"/>
        <source>monitor only: writes blocked</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/status_panel.py" line="299"/>
        <source>{ms} ms</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/status_panel.py" line="312"/>
        <source>GV291 code: {code}</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/status_panel.py" line="320"/>
        <source>Raw words {first}..{last}: {words}</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/status_panel.py" line="324"/>
        <source>Controller clock minus PC clock</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/status_panel.py" line="328"/>
        <source>invalid date/time</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/status_panel.py" line="335"/>
        <source>{drift} s</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>StepPanel</name>
    <message>
        <location filename="../../ui/step_panel.py" line="159"/>
        <source>Frame:</source>
        <translation>坐标系：</translation>
    </message>
    <message>
        <location filename="../../ui/step_panel.py" line="160"/>
        <source>Joint frame</source>
        <translation>关节坐标系</translation>
    </message>
    <message>
        <location filename="../../ui/step_panel.py" line="161"/>
        <source>Base frame</source>
        <translation>基坐标系</translation>
    </message>
    <message>
        <location filename="../../ui/step_panel.py" line="162"/>
        <source>Speed:</source>
        <translation>速度：</translation>
    </message>
    <message>
        <location filename="../../ui/step_panel.py" line="163"/>
        <source>Expected speed of the incremental move (GV225)</source>
        <translation>增量运动的期望速度（GV225）</translation>
    </message>
    <message>
        <location filename="../../ui/step_panel.py" line="164"/>
        <source>Increment per click (mm or °)</source>
        <translation>每次点击的增量（mm 或 °）</translation>
    </message>
    <message>
        <location filename="../../ui/step_panel.py" line="165"/>
        <source>Incremental move</source>
        <translation>增量运动</translation>
    </message>
    <message>
        <location filename="../../ui/step_panel.py" line="166"/>
        <source>Exact offset</source>
        <translation>精确偏移量</translation>
    </message>
    <message>
        <location filename="../../ui/step_panel.py" line="167"/>
        <source>Move by values</source>
        <translation>按数值运动</translation>
    </message>
    <message>
        <location filename="../../ui/step_panel.py" line="168"/>
        <source>Move every axis by its exact offset in one incremental move</source>
        <translation>以一次增量运动使各轴移动其精确偏移量</translation>
    </message>
    <message>
        <location filename="../../ui/step_panel.py" line="169"/>
        <source>Clear values</source>
        <translation>清除数值</translation>
    </message>
    <message>
        <location filename="../../ui/step_panel.py" line="170"/>
        <source>External axes J7–J11</source>
        <translation>外部轴 J7–J11</translation>
    </message>
    <message>
        <location filename="../../ui/step_panel.py" line="171"/>
        <source>Show the external axes; while hidden their offsets are 0</source>
        <translation>显示外部轴；隐藏时其偏移量为 0</translation>
    </message>
    <message>
        <location filename="../../ui/step_panel.py" line="200"/>
        <source>rpm</source>
        <translation>转/分</translation>
    </message>
    <message>
        <location filename="../../ui/step_panel.py" line="200"/>
        <source>mm/s</source>
        <translation>mm/s</translation>
    </message>
    <message>
        <location filename="../../ui/step_panel.py" line="248"/>
        <source>Move by {moves} at {speed} {unit}?</source>
        <translation>以 {speed} {unit} 运动 {moves}？</translation>
    </message>
    <message>
        <location filename="../../ui/step_panel.py" line="250"/>
        <source>Confirm incremental move</source>
        <translation>确认增量运动</translation>
    </message>
    <message>
        <location filename="../../ui/step_panel.py" line="274"/>
        <source>°</source>
        <translation>°</translation>
    </message>
    <message>
        <location filename="../../ui/step_panel.py" line="274"/>
        <source>mm</source>
        <translation>mm</translation>
    </message>
</context>
<context>
    <name>TrafficModel</name>
    <message>
        <location filename="../../ui/traffic_panel.py" line="216"/>
        <source>Time</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/traffic_panel.py" line="217"/>
        <source>Dir</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/traffic_panel.py" line="218"/>
        <source>Bytes</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/traffic_panel.py" line="219"/>
        <source>Meaning</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/traffic_panel.py" line="221"/>
        <source>→ Tx</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/traffic_panel.py" line="222"/>
        <source>← Rx</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/traffic_panel.py" line="386"/>
        <source>{n} bytes</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>TrafficPanel</name>
    <message>
        <location filename="../../ui/traffic_panel.py" line="531"/>
        <source>Filter: bytes or meaning</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/traffic_panel.py" line="532"/>
        <source>Hide polls</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/traffic_panel.py" line="534"/>
        <source>Hide the periodic reads of 412.. (pose) and 560.. (status)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/traffic_panel.py" line="536"/>
        <source>Pause capture</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/traffic_panel.py" line="537"/>
        <source>Stop recording frames (the worker stops building them)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/traffic_panel.py" line="538"/>
        <source>Clear</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/traffic_panel.py" line="539"/>
        <source>Export…</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/traffic_panel.py" line="659"/>
        <location filename="../../ui/traffic_panel.py" line="670"/>
        <source>Export traffic</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/traffic_panel.py" line="661"/>
        <source>CSV files (*.csv);;Text files (*.txt);;All files (*)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/traffic_panel.py" line="671"/>
        <source>Could not write {path}: {error}</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/traffic_panel.py" line="699"/>
        <source>{n} frames</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/traffic_panel.py" line="701"/>
        <source>{shown} of {n} frames shown</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../ui/traffic_panel.py" line="703"/>
        <source>capture paused</source>
        <translation type="unfinished"></translation>
    </message>
</context>
</TS>
