<?xml version="1.0" encoding="utf-8"?>
<!DOCTYPE TS>
<TS version="2.1" language="zh_CN">
    <context>
        <name>AlarmBanner</name>
        <message>
            <location filename="../../ui/panels/alarm_banner.py" line="73" />
            <source>alarm bit {bit}</source>
            <translation>报警位 {bit}</translation>
        </message>
        <message>
            <location filename="../../ui/panels/alarm_banner.py" line="198" />
            <source>ALARM: {names}</source>
            <translation>报警：{names}</translation>
        </message>
        <message>
            <location filename="../../ui/panels/alarm_banner.py" line="200" />
            <source>(last known: the link is not live)</source>
            <translation>（最后已知：通信未实时）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/alarm_banner.py" line="203" />
            <source>Motion controls are held until the alarm is reset. STOP stays available.</source>
            <translation>报警复位前运动控制已锁定。停止按钮始终可用。</translation>
        </message>
        <message>
            <location filename="../../ui/panels/alarm_banner.py" line="210" />
            <source>Register 562 = {word}</source>
            <translation>寄存器 562 = {word}</translation>
        </message>
    </context>
    <context>
        <name>AlarmListPanel</name>
        <message>
            <location filename="../../ui/panels/alarm_list.py" line="93" />
            <source>Alarm</source>
            <translation>报警</translation>
        </message>
        <message>
            <location filename="../../ui/panels/alarm_list.py" line="94" />
            <source>Meaning</source>
            <translation>含义</translation>
        </message>
        <message>
            <location filename="../../ui/panels/alarm_list.py" line="95" />
            <source>What to do</source>
            <translation>处理方法</translation>
        </message>
        <message>
            <location filename="../../ui/panels/alarm_list.py" line="96" />
            <source>Raised</source>
            <translation>触发时间</translation>
        </message>
        <message>
            <location filename="../../ui/panels/alarm_list.py" line="97" />
            <source>Cleared</source>
            <translation>清除时间</translation>
        </message>
        <message>
            <location filename="../../ui/panels/alarm_list.py" line="117" />
            <location filename="../../ui/panels/alarm_list.py" line="125" />
            <source>active</source>
            <translation>未清除</translation>
        </message>
        <message>
            <location filename="../../ui/panels/alarm_list.py" line="123" />
            <source>raised {raised}, cleared {cleared}</source>
            <translation>触发 {raised}，清除 {cleared}</translation>
        </message>
    </context>
    <context>
        <name>Alarms</name>
        <message>
            <location filename="../../app/alarm_history.py" line="37" />
            <source>The emergency stop circuit is open: servo power is off.</source>
            <translation>急停回路断开：伺服已断电。</translation>
        </message>
        <message>
            <location filename="../../app/alarm_history.py" line="38" />
            <source>A servo drive reported a fault.</source>
            <translation>伺服驱动器报告故障。</translation>
        </message>
        <message>
            <location filename="../../app/alarm_history.py" line="39" />
            <source>A holding brake did not release or engage as commanded.</source>
            <translation>抱闸未按指令松开或抱紧。</translation>
        </message>
        <message>
            <location filename="../../app/alarm_history.py" line="40" />
            <source>The motion planner rejected a move (out of reach, singularity or limit).</source>
            <translation>运动规划拒绝了该运动（超出范围、奇异点或限位）。</translation>
        </message>
        <message>
            <location filename="../../app/alarm_history.py" line="43" />
            <source>An axis encoder angle is implausible or was lost.</source>
            <translation>某轴编码器角度异常或丢失。</translation>
        </message>
        <message>
            <location filename="../../app/alarm_history.py" line="46" />
            <source>Make the cell safe, release the emergency stop button, then reset the alarm on the controller.</source>
            <translation>确认现场安全，松开急停按钮，然后在控制器上复位报警。</translation>
        </message>
        <message>
            <location filename="../../app/alarm_history.py" line="50" />
            <source>Read the drive's fault code on the controller, remove the cause, then reset the alarm.</source>
            <translation>在控制器上查看驱动器故障码，排除原因后复位报警。</translation>
        </message>
        <message>
            <location filename="../../app/alarm_history.py" line="53" />
            <source>Do not move the arm; check the brake wiring and power, then reset the alarm.</source>
            <translation>不要移动机械臂；检查抱闸接线和电源，然后复位报警。</translation>
        </message>
        <message>
            <location filename="../../app/alarm_history.py" line="56" />
            <source>Check the target point and speed, reset the alarm, then move to a reachable point.</source>
            <translation>检查目标点和速度，复位报警，然后移动到可达的点。</translation>
        </message>
        <message>
            <location filename="../../app/alarm_history.py" line="59" />
            <source>Check the encoder cable; the zero position may need recalibration before moving.</source>
            <translation>检查编码器电缆；运动前可能需要重新标定零点。</translation>
        </message>
        <message>
            <location filename="../../app/alarm_history.py" line="63" />
            <source>A bit the protocol does not document.</source>
            <translation>协议未说明的报警位。</translation>
        </message>
        <message>
            <location filename="../../app/alarm_history.py" line="64" />
            <source>Read the alarm on the controller's own pendant.</source>
            <translation>请在控制器自带的示教器上查看报警。</translation>
        </message>
    </context>
    <context>
        <name>AuditModel</name>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="68" />
            <source>Time</source>
            <translation>时间</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="69" />
            <source>Role</source>
            <translation>角色</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="70" />
            <source>Kind</source>
            <translation>类型</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="71" />
            <source>Command</source>
            <translation>命令</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="72" />
            <source>Result</source>
            <translation>结果</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="73" />
            <source>Detail</source>
            <translation>详情</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="89" />
            <source>plant ({robot})</source>
            <translation>工厂系统（{robot}）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="98" />
            <source>operator</source>
            <translation>操作员</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="99" />
            <source>engineer</source>
            <translation>工程师</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="100" />
            <source>administrator</source>
            <translation>管理员</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="101" />
            <source>administrator (CLI)</source>
            <translation>管理员（命令行）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="102" />
            <source>write</source>
            <translation>写入</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="103" />
            <source>refused</source>
            <translation>已拒绝</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="104" />
            <source>login</source>
            <translation>登录</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="105" />
            <source>action</source>
            <translation>操作</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="106" />
            <source>answered</source>
            <translation>已应答</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="110" />
            <source>done</source>
            <translation>完成</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="111" />
            <source>stopped</source>
            <translation>已停止</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="107" />
            <source>failed</source>
            <translation>失败</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="108" />
            <source>blocked</source>
            <translation>已阻止</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="109" />
            <source>unknown</source>
            <translation>未知</translation>
        </message>
    </context>
    <context>
        <name>AuditViewer</name>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="127" />
            <source>Audit trail</source>
            <translation>审计记录</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="137" />
            <source>Any role</source>
            <translation>任意角色</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="139" />
            <source>operator</source>
            <translation>操作员</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="140" />
            <source>engineer</source>
            <translation>工程师</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="141" />
            <source>administrator</source>
            <translation>管理员</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="142" />
            <source>administrator (CLI)</source>
            <translation>管理员（命令行）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="147" />
            <source>Command contains…</source>
            <translation>命令包含…</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="149" />
            <source>Any result</source>
            <translation>任意结果</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="156" />
            <source>failed</source>
            <translation>失败</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="157" />
            <source>blocked</source>
            <translation>已阻止</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="152" />
            <source>refused</source>
            <translation>已拒绝</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="143" />
            <source>plant</source>
            <translation>工厂系统</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="151" />
            <source>done</source>
            <translation>完成</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="153" />
            <source>stopped</source>
            <translation>已停止</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="154" />
            <source>unknown</source>
            <translation>未知</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="155" />
            <source>answered</source>
            <translation>已应答</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="160" />
            <source>Show</source>
            <translation>显示</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="162" />
            <source>Export CSV…</source>
            <translation>导出 CSV…</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="172" />
            <source>From</source>
            <translation>从</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="172" />
            <source>to</source>
            <translation>到</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="205" />
            <source>{n} records</source>
            <translation>{n} 条记录</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="207" />
            <source>{n} records ({skipped} damaged lines skipped)</source>
            <translation>{n} 条记录（跳过 {skipped} 行损坏的记录）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="209" />
            <source>{unknown} writes whose answer or outcome was not recorded</source>
            <translation>{unknown} 条写入的应答或结果未记录</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="221" />
            <source>The chain of hashes breaks at {file} line {line}: records before it were removed.</source>
            <translation>哈希链在 {file} 第 {line} 行断开：此前的记录已被删除。</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="225" />
            <source>The chain of hashes breaks at {file} line {line}: the record before it was changed, or records were removed.</source>
            <translation>哈希链在 {file} 第 {line} 行断开：此前的记录被修改，或有记录被删除。</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="230" />
            <source>{n} breaks in all.</source>
            <translation>共 {n} 处断开。</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="233" />
            <source>(No chain of hashes: records of an older TeachPad.)</source>
            <translation>（无哈希链：旧版 TeachPad 的记录。）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="238" />
            <source>Export the audit trail</source>
            <translation>导出审计记录</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="238" />
            <source>CSV files (*.csv)</source>
            <translation>CSV 文件 (*.csv)</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="252" />
            <source>Cannot write {file}: {why}</source>
            <translation>无法写入 {file}：{why}</translation>
        </message>
        <message>
            <location filename="../../ui/panels/audit_viewer.py" line="255" />
            <source>{n} records exported to {file}</source>
            <translation>已将 {n} 条记录导出到 {file}</translation>
        </message>
    </context>
    <context>
        <name>AuditWords</name>
        <message>
            <location filename="../../ui/audit_words.py" line="41" />
            <source>jog</source>
            <translation>点动</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="42" />
            <source>step</source>
            <translation>增量运动</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="43" />
            <source>teach</source>
            <translation>示教点</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="44" />
            <source>run plan</source>
            <translation>运行轨迹</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="45" />
            <source>run program</source>
            <translation>运行程序</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="46" />
            <source>stop</source>
            <translation>停止</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="47" />
            <source>reduced speed</source>
            <translation>降速模式</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="48" />
            <source>edit points</source>
            <translation>编辑点位</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="49" />
            <source>edit plans</source>
            <translation>编辑轨迹</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="50" />
            <source>edit envelope</source>
            <translation>编辑安全范围</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="51" />
            <source>change robot model</source>
            <translation>更换机器人模型</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="52" />
            <source>leave reduced speed</source>
            <translation>退出降速模式</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="53" />
            <source>reconnect to the same controller</source>
            <translation>重新连接同一控制器</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="54" />
            <source>change connection</source>
            <translation>更改连接</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="55" />
            <source>change register profile</source>
            <translation>更改寄存器配置</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="56" />
            <source>manage roles and passwords</source>
            <translation>管理角色与密码</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="57" />
            <source>write a support bundle</source>
            <translation>生成支持包</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="58" />
            <source>write controller registers directly</source>
            <translation>直接写控制器寄存器</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="59" />
            <source>move to point</source>
            <translation>运动到点</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="60" />
            <source>set the idle lock time</source>
            <translation>设置空闲锁定时间</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="61" />
            <source>reduced speed on</source>
            <translation>开启降速模式</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="62" />
            <source>stop measured</source>
            <translation>停止已测量</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="63" />
            <source>jog release measured</source>
            <translation>点动松开已测量</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="64" />
            <source>reduced speed off</source>
            <translation>关闭降速模式</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="65" />
            <source>clear the administrator password</source>
            <translation>清除管理员密码</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="70" />
            <source>operator</source>
            <translation>操作员</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="71" />
            <source>engineer</source>
            <translation>工程师</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="72" />
            <source>administrator</source>
            <translation>管理员</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="77" />
            <source>log in as {role}</source>
            <translation>以{role}身份登录</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="78" />
            <source>log out ({role})</source>
            <translation>注销（{role}）</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="81" />
            <source>set the {role} password</source>
            <translation>设置{role}密码</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="85" />
            <source>change the {role} password</source>
            <translation>更改{role}密码</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="89" />
            <source>clear the {role} password</source>
            <translation>清除{role}密码</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="93" />
            <source>locked back to operator after {seconds} s idle</source>
            <translation>空闲 {seconds} s 后锁回操作员</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="98" />
            <source>{action} ({register})</source>
            <translation>{action}（{register}）</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="100" />
            <source>write {what}</source>
            <translation>写入 {what}</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="103" />
            <source>sent; TeachPad stopped before the answer was recorded</source>
            <translation>已发送；记录应答之前 TeachPad 已停止</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="104" />
            <source>sent and answered; the controller's outcome was not recorded (still under way when read, or TeachPad stopped first)</source>
            <translation>已发送并已应答；未记录控制器的结果（读取时仍在进行，或 TeachPad 先停止了）</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="234" />
            <source>not sent: the controller is busy (program {state}); wait for it to end, or stop it</source>
            <translation>未发送：控制器忙（程序{state}）；请等它结束，或将其停止</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="241" />
            <source>wrong password for the {role} role</source>
            <translation>{role}角色的密码错误</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="246" />
            <source>no password is set for the {role} role; an administrator sets it</source>
            <translation>{role}角色尚未设置密码；由管理员设置</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="254" />
            <source>the {role} role needs its password: run it in a terminal, or set {env}</source>
            <translation>{role}角色需要密码：请在终端中运行，或设置 {env}</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="262" />
            <source>the administrator password is needed: run it in a terminal, or set {env}</source>
            <translation>需要管理员密码：请在终端中运行，或设置 {env}</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="269" />
            <source>wrong administrator password</source>
            <translation>管理员密码错误</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="274" />
            <source>the administrator password can be changed, not removed (anyone could then set it)</source>
            <translation>管理员密码只能修改，不能清除（否则任何人都可以重新设置它）</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="287" />
            <source>P{id} cannot be checked against the safety envelope: the host has no copy of it (give the project holding the point with {option})</source>
            <translation>P{id} 无法对照安全范围检查：主机没有它的副本（请用 {option} 给出含有该点的工程）</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="314" />
            <source>another Modbus master wrote to the controller less than {hold} s ago</source>
            <translation>另一个 Modbus 主站在不到 {hold} s 前写过控制器</translation>
        </message>
        <message>
            <location filename="../../ui/audit_words.py" line="374" />
            <source>needs the {need} role ({role} was logged in)</source>
            <translation>需要{need}角色（当时登录的是{role}）</translation>
        </message>
    </context>
    <context>
        <name>CellHost</name>
        <message>
            <location filename="../../ui/window_cell.py" line="73" />
            <source>Open cell</source>
            <extracomment>the window's settings of the plant link: on (off by default), broker URL, group, node</extracomment>
            <translation>打开单元</translation>
        </message>
        <message>
            <location filename="../../ui/window_cell.py" line="73" />
            <source>Cell files (*.json);;All files (*)</source>
            <translation>单元文件 (*.json);;所有文件 (*)</translation>
        </message>
        <message>
            <location filename="../../ui/window_cell.py" line="84" />
            <source>Cell file</source>
            <translation>单元文件</translation>
        </message>
        <message>
            <location filename="../../ui/window_cell.py" line="100" />
            <location filename="../../ui/window_cell.py" line="133" />
            <location filename="../../ui/window_cell.py" line="275" />
            <source>Cell</source>
            <translation>单元</translation>
        </message>
        <message>
            <location filename="../../ui/window_cell.py" line="128" />
            <location filename="../../ui/window_cell.py" line="276" />
            <source>Cell {name}</source>
            <translation>单元 {name}</translation>
        </message>
        <message>
            <location filename="../../ui/window_cell.py" line="160" />
            <source>Take control of {name} ({where})?

The pendant connects to it and commands it; every other robot of the cell stays monitor-only.</source>
            <translation>接管 {name}（{where}）的控制？

示教器将连接并控制它；单元中其他机器人保持仅监视。</translation>
        </message>
        <message>
            <location filename="../../ui/window_cell.py" line="163" />
            <source>Take control</source>
            <translation>接管控制</translation>
        </message>
        <message>
            <location filename="../../ui/window_cell.py" line="179" />
            <location filename="../../ui/window_cell.py" line="187" />
            <source>Export history</source>
            <translation>导出历史</translation>
        </message>
        <message>
            <location filename="../../ui/window_cell.py" line="179" />
            <source>CSV files (*.csv)</source>
            <translation>CSV 文件 (*.csv)</translation>
        </message>
        <message>
            <location filename="../../ui/window_cell.py" line="188" />
            <source>Cannot write {path}: {error}</source>
            <translation>无法写入 {path}：{error}</translation>
        </message>
        <message>
            <location filename="../../ui/window_cell.py" line="270" />
            <source>Open &amp;cell…</source>
            <translation>打开单元(&amp;C)…</translation>
        </message>
        <message>
            <location filename="../../ui/window_cell.py" line="271" />
            <source>Watch every controller of a cell file, monitor only</source>
            <translation>监视单元文件中的每台控制器（仅监视）</translation>
        </message>
    </context>
    <context>
        <name>CellPanel</name>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="560" />
            <source>MQTT: published</source>
            <translation>MQTT：已发布</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="561" />
            <source>Published to {where}</source>
            <translation>已发布到 {where}</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="563" />
            <source>MQTT: connecting…</source>
            <translation>MQTT：正在连接…</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="564" />
            <source>Connecting to {where}…</source>
            <translation>正在连接 {where}…</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="582" />
            <source>History of {name}</source>
            <translation>{name} 的历史</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="591" />
            <source>Cell {name}: {count} controllers, monitor only</source>
            <translation>单元 {name}：{count} 台控制器，仅监视</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="595" />
            <source>Back to the cell</source>
            <translation>返回单元</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="596" />
            <source>Whole window</source>
            <translation>整个窗口</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="597" />
            <source>Plant link…</source>
            <translation>工厂链路…</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="599" />
            <source>Publish this cell to an MQTT broker (Sparkplug B), as teachpad-gateway</source>
            <translation>将本单元发布到 MQTT 代理（Sparkplug B），与 teachpad-gateway 相同</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="602" />
            <source>Show the cell in a window of its own (16 tiles at a glance)</source>
            <translation>在单独窗口中显示单元（一眼看到 16 个磁贴）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="603" />
            <source>Export CSV…</source>
            <translation>导出 CSV…</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="604" />
            <source>Time</source>
            <translation>时间</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="604" />
            <source>Event</source>
            <translation>事件</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="604" />
            <source>Detail</source>
            <translation>详情</translation>
        </message>
    </context>
    <context>
        <name>CellPublishDialog</name>
        <message>
            <location filename="../../ui/dialogs/cell_publish_dialog.py" line="36" />
            <source>Plant link</source>
            <translation>工厂链路</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/cell_publish_dialog.py" line="40" />
            <source>Publish every controller of the cell to an MQTT broker as a Sparkplug B edge node, as teachpad-gateway does (read only: nothing is written to a controller). A broker password comes from the environment variable {name}, never from the settings.</source>
            <translation>像 teachpad-gateway 一样，将单元中的每台控制器作为 Sparkplug B 边缘节点发布到 MQTT 代理（只读：不向任何控制器写入）。代理密码只来自环境变量 {name}，从不保存在设置中。</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/cell_publish_dialog.py" line="48" />
            <source>Publish this cell</source>
            <translation>发布本单元</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/cell_publish_dialog.py" line="57" />
            <source>Broker:</source>
            <translation>代理：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/cell_publish_dialog.py" line="58" />
            <source>Group:</source>
            <translation>组：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/cell_publish_dialog.py" line="59" />
            <source>Node:</source>
            <translation>节点：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/cell_publish_dialog.py" line="88" />
            <source>The broker must be mqtt://HOST[:PORT] or mqtts://HOST[:PORT] (a user name may come before the host, USER@HOST; the password only from {name}).</source>
            <translation>代理必须是 mqtt://HOST[:PORT] 或 mqtts://HOST[:PORT]（主机前可带用户名，USER@HOST；密码只能来自 {name}）。</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/cell_publish_dialog.py" line="92" />
            <source>The group and the node must not be empty nor contain '/', '+' or '#'.</source>
            <translation>组和节点不能为空，也不能包含 '/'、'+' 或 '#'。</translation>
        </message>
    </context>
    <context>
        <name>CellTile</name>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="264" />
            <source>{name} (in control)</source>
            <translation>{name}（控制中）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="267" />
            <source>not answering {seconds} s</source>
            <translation>无应答 {seconds} 秒</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="269" />
            <source>answering</source>
            <translation>正在应答</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="286" />
            <source>no answer, {errors} err/min</source>
            <translation>尚无应答 错误{errors}/分</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="288" />
            <source>no answer yet, {errors} errors/min</source>
            <translation>尚无应答，{errors} 次错误/分钟</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="293" />
            <source>{age} s, RTT {rtt} ms, {errors} err/min</source>
            <translation>{age}秒 往返{rtt}ms 错误{errors}/分</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="295" />
            <source>{age} s ago, RTT {rtt} ms, {errors} errors/min</source>
            <translation>{age} 秒前，往返 {rtt} 毫秒，{errors} 次错误/分钟</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="314" />
            <source>mode {mode}, program {program}</source>
            <translation>模式 {mode}，程序 {program}</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="314" />
            <source>{mode}, {program}</source>
            <translation>{mode}，{program}</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="335" />
            <source>{alarm} +{more}</source>
            <translation>{alarm} +{more}</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="339" />
            <source>alarms: {alarms}</source>
            <translation>报警：{alarms}</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="352" />
            <source>Take control or see the history of {name}</source>
            <translation>接管 {name} 的控制或查看其历史</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="333" />
            <source>no alarm</source>
            <translation>无报警</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="347" />
            <location filename="../../ui/panels/cell_panel.py" line="349" />
            <source>Take control…</source>
            <translation>接管控制…</translation>
        </message>
        <message>
            <location filename="../../ui/panels/cell_panel.py" line="348" />
            <location filename="../../ui/panels/cell_panel.py" line="350" />
            <source>History</source>
            <translation>历史</translation>
        </message>
    </context>
    <context>
        <name>ComparePoints</name>
        <message>
            <location filename="../../ui/window_compare.py" line="48" />
            <source>Compare &amp;with…</source>
            <translation>比较(&amp;W)…</translation>
        </message>
        <message>
            <location filename="../../ui/window_compare.py" line="51" />
            <source>Compare the project's points with another project or a points CSV: added, removed, moved</source>
            <translation>将本项目的点与另一个项目或点位 CSV 比较：新增、删除、移动</translation>
        </message>
        <message>
            <location filename="../../ui/window_compare.py" line="64" />
            <source>Compare with</source>
            <translation>比较对象</translation>
        </message>
        <message>
            <location filename="../../ui/window_compare.py" line="64" />
            <source>Projects and points CSV (*.json *.csv);;All files (*)</source>
            <translation>项目和点位 CSV (*.json *.csv);;所有文件 (*)</translation>
        </message>
        <message>
            <location filename="../../ui/window_compare.py" line="75" />
            <location filename="../../ui/window_compare.py" line="78" />
            <source>Cannot compare</source>
            <translation>无法比较</translation>
        </message>
    </context>
    <context>
        <name>ComparePointsDialog</name>
        <message>
            <location filename="../../ui/dialogs/compare_points.py" line="107" />
            <source>Compare points</source>
            <translation>比较点位</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/compare_points.py" line="108" />
            <source>Distance tolerance (mm):</source>
            <translation>距离容差 (mm)：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/compare_points.py" line="109" />
            <source>Angle tolerance (°):</source>
            <translation>角度容差 (°)：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/compare_points.py" line="112" />
            <source>Change</source>
            <translation>变化</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/compare_points.py" line="113" />
            <source>Point</source>
            <translation>点</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/compare_points.py" line="114" />
            <source>Distance (mm)</source>
            <translation>距离 (mm)</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/compare_points.py" line="115" />
            <source>Turn (°)</source>
            <translation>转角 (°)</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/compare_points.py" line="116" />
            <source>dx, dy, dz (mm)</source>
            <translation>dx, dy, dz (mm)</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/compare_points.py" line="117" />
            <source>Tool</source>
            <translation>工具</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/compare_points.py" line="130" />
            <source>A: {a} (points: {n})</source>
            <translation>A：{a}（{n} 个点）</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/compare_points.py" line="132" />
            <source>B: {b} (points: {n})</source>
            <translation>B：{b}（{n} 个点）</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/compare_points.py" line="136" />
            <source>Differences: {n}; points the same: {same}</source>
            <translation>{n} 处不同；{same} 个点相同</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/compare_points.py" line="139" />
            <source>The same within the tolerances (points: {n})</source>
            <translation>在容差范围内相同（{n} 个点）</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/compare_points.py" line="146" />
            <source>added in B</source>
            <translation>B 中新增</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/compare_points.py" line="147" />
            <source>removed in B</source>
            <translation>B 中删除</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/compare_points.py" line="148" />
            <source>moved</source>
            <translation>已移动</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/compare_points.py" line="149" />
            <source>other tool</source>
            <translation>工具不同</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/compare_points.py" line="175" />
            <source>In A:</source>
            <translation>在 A 中：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/compare_points.py" line="177" />
            <source>In B:</source>
            <translation>在 B 中：</translation>
        </message>
    </context>
    <context>
        <name>ConnectionDialog</name>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="200" />
            <source>Connect to controller</source>
            <translation>连接控制器</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="201" />
            <source>Transport:</source>
            <translation>通信方式：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="202" />
            <location filename="../../ui/dialogs/connection_dialog.py" line="261" />
            <source>Modbus TCP</source>
            <translation>Modbus TCP</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="203" />
            <location filename="../../ui/dialogs/connection_dialog.py" line="261" />
            <source>Modbus RTU (serial)</source>
            <translation>Modbus RTU（串口）</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="204" />
            <source>Host:</source>
            <translation>主机：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="205" />
            <source>Port:</source>
            <translation>端口：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="206" />
            <source>Serial port:</source>
            <translation>串口：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="207" />
            <source>Refresh</source>
            <translation>刷新</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="208" />
            <source>List the serial ports of this computer again</source>
            <translation>重新列出本机的串口</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="210" />
            <source>Baud rate:</source>
            <translation>波特率：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="211" />
            <source>Parity:</source>
            <translation>校验位：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="212" />
            <source>none</source>
            <translation>无</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="212" />
            <source>even</source>
            <translation>偶校验</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="212" />
            <source>odd</source>
            <translation>奇校验</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="214" />
            <source>Stop bits:</source>
            <translation>停止位：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="215" />
            <source>Unit id:</source>
            <translation>从站地址：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="216" />
            <source>Float word order:</source>
            <translation>浮点数字序：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="217" />
            <source>Low word first (CDAB, default)</source>
            <translation>低字在前（CDAB，默认）</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="218" />
            <source>High word first (ABCD)</source>
            <translation>高字在前（ABCD）</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="219" />
            <source>Timeout:</source>
            <translation>超时：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="220" />
            <source>Monitor only (never write to the controller)</source>
            <translation>仅监视（从不写入控制器）</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="223" />
            <source>Unit id and word order come from the register profile (Safety → Register profile…, administrator).</source>
            <translation>从站地址和字序取自寄存器配置（安全 → 寄存器配置…，管理员）。</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="263" />
            <source>Connected to {where}</source>
            <translation>已连接到 {where}</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="264" />
            <source>Connecting to {where}</source>
            <translation>正在连接 {where}</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="265" />
            <source>Connected to {where}, but the controller does not answer</source>
            <translation>已连接到 {where}，但控制器没有应答</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="266" />
            <source>Connection to {where} lost; retrying</source>
            <translation>与 {where} 的连接已断开，正在重试</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="267" />
            <source>Not connected (last: {where})</source>
            <translation>未连接（上次：{where}）</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="271" />
            <source>{transport}, unit {unit}</source>
            <translation>{transport}，从站地址 {unit}</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="274" />
            <source>Polling at {hz:g} Hz</source>
            <translation>轮询频率 {hz:g} Hz</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="276" />
            <source>Monitor only: nothing is written to the controller</source>
            <translation>仅监视：不向控制器写入任何内容</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="304" />
            <source>Could not list the serial ports ({error}); type the device name</source>
            <translation>无法列出串口（{error}），请直接输入设备名</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="308" />
            <source>Serial ports found: {n}</source>
            <translation>找到的串口：{n} 个</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="310" />
            <source>No serial port found; type the device name</source>
            <translation>未找到串口，请直接输入设备名</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="363" />
            <source>a serial port is needed for RTU</source>
            <translation>RTU 方式需要指定串口</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="376" />
            <source>it contains a space</source>
            <translation>其中含有空格</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="377" />
            <source>it is longer than 253 characters</source>
            <translation>长度超过 253 个字符</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="378" />
            <source>it has an empty part (two dots in a row, or a dot at the start)</source>
            <translation>其中有空的部分（两个点相连，或以点开头）</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="379" />
            <source>a part between two dots is longer than 63 characters</source>
            <translation>两个点之间的某一部分超过 63 个字符</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="380" />
            <source>it contains a character a host name cannot have</source>
            <translation>其中含有主机名不允许的字符</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="381" />
            <source>a part between two dots starts or ends with a hyphen</source>
            <translation>两个点之间的某一部分以连字符开头或结尾</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="382" />
            <source>it looks like an IP address but is not one</source>
            <translation>看起来像 IP 地址，但不是有效的 IP 地址</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/connection_dialog.py" line="384" />
            <source>Not a valid host name or IP address: {why}.</source>
            <translation>不是有效的主机名或 IP 地址：{why}。</translation>
        </message>
    </context>
    <context>
        <name>ControlBar</name>
        <message>
            <location filename="../../ui/panels/control_bar.py" line="131" />
            <source>STOP</source>
            <translation>停止</translation>
        </message>
        <message>
            <location filename="../../ui/panels/control_bar.py" line="132" />
            <source>Stop all motion (Esc)</source>
            <translation>停止所有运动（Esc）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/control_bar.py" line="133" />
            <source>Pause</source>
            <translation>暂停</translation>
        </message>
        <message>
            <location filename="../../ui/panels/control_bar.py" line="134" />
            <source>Pause the current move or program</source>
            <translation>暂停当前运动或程序</translation>
        </message>
        <message>
            <location filename="../../ui/panels/control_bar.py" line="135" />
            <source>Resume</source>
            <translation>继续</translation>
        </message>
        <message>
            <location filename="../../ui/panels/control_bar.py" line="136" />
            <source>Resume the paused move or program</source>
            <translation>继续已暂停的运动或程序</translation>
        </message>
        <message>
            <location filename="../../ui/panels/control_bar.py" line="224" />
            <source>unknown</source>
            <translation>未知</translation>
        </message>
        <message>
            <location filename="../../ui/panels/control_bar.py" line="228" />
            <source>The controller's work mode (register 560)</source>
            <translation>控制器工作模式（寄存器 560）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/control_bar.py" line="137" />
            <source>Manual</source>
            <translation>手动</translation>
        </message>
        <message>
            <location filename="../../ui/panels/control_bar.py" line="138" />
            <source>Switch the controller to manual mode</source>
            <translation>将控制器切换到手动模式</translation>
        </message>
        <message>
            <location filename="../../ui/panels/control_bar.py" line="139" />
            <source>Auto</source>
            <translation>自动</translation>
        </message>
        <message>
            <location filename="../../ui/panels/control_bar.py" line="140" />
            <source>Switch the controller to auto mode (needed for Modbus motion)</source>
            <translation>将控制器切换到自动模式（Modbus 运动需要自动模式）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/control_bar.py" line="225" />
            <location filename="../../ui/panels/control_bar.py" line="226" />
            <source>Mode:
{mode}</source>
            <translation>模式：
{mode}</translation>
        </message>
    </context>
    <context>
        <name>DryRunBar</name>
        <message>
            <location filename="../../ui/panels/view3d_dryrun.py" line="70" />
            <source>Dry run:</source>
            <translation>空运行：</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_dryrun.py" line="71" />
            <source>Pause</source>
            <translation>暂停</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_dryrun.py" line="71" />
            <source>Play</source>
            <translation>播放</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_dryrun.py" line="72" />
            <source>Play the plan on the drawn arm; nothing is sent to the robot</source>
            <translation>在绘制的机械臂上播放轨迹；不向机器人发送任何指令</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_dryrun.py" line="73" />
            <source>Live arm</source>
            <translation>实时机械臂</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_dryrun.py" line="74" />
            <source>Leave the dry run and show the robot's arm again</source>
            <translation>退出空运行，重新显示机器人的机械臂</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_dryrun.py" line="75" />
            <source>Speed of the dry run, times the planned speed</source>
            <translation>空运行速度（规划速度的倍数）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_dryrun.py" line="76" />
            <source>Drag to any moment of the plan</source>
            <translation>拖动到轨迹的任意时刻</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_dryrun.py" line="177" />
            <source>loop %1 (endless: every later loop is the same)</source>
            <translation>第 %1 轮（无限循环：之后每轮都相同）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_dryrun.py" line="178" />
            <source>loop %1 of %2</source>
            <translation>第 %1 轮（共 %2 轮）</translation>
        </message>
    </context>
    <context>
        <name>EnvelopeDialog</name>
        <message>
            <location filename="../../ui/dialogs/envelope_dialog.py" line="54" />
            <source>Safety envelope</source>
            <translation>安全范围</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/envelope_dialog.py" line="56" />
            <source>Check joint limits</source>
            <translation>检查关节限位</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/envelope_dialog.py" line="59" />
            <source>Min (°)</source>
            <translation>最小 (°)</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/envelope_dialog.py" line="59" />
            <source>Max (°)</source>
            <translation>最大 (°)</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/envelope_dialog.py" line="66" />
            <source>Keep the TCP inside this box</source>
            <translation>TCP 必须留在此长方体内</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/envelope_dialog.py" line="75" />
            <source>Name</source>
            <translation>名称</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/envelope_dialog.py" line="76" />
            <source>{axis} min</source>
            <translation>{axis} 最小</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/envelope_dialog.py" line="77" />
            <source>{axis} max</source>
            <translation>{axis} 最大</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/envelope_dialog.py" line="84" />
            <source>Add zone</source>
            <translation>添加禁区</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/envelope_dialog.py" line="86" />
            <source>Remove zone</source>
            <translation>删除禁区</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/envelope_dialog.py" line="96" />
            <source>Revision {n}</source>
            <translation>版本 {n}</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/envelope_dialog.py" line="100" />
            <source>Joint limits</source>
            <translation>关节限位</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/envelope_dialog.py" line="104" />
            <source>Work space (keep-in box)</source>
            <translation>工作空间（允许区域）</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/envelope_dialog.py" line="113" />
            <source>Keep-out zones</source>
            <translation>禁入区域</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/envelope_dialog.py" line="121" />
            <source>Speeds</source>
            <translation>速度</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/envelope_dialog.py" line="123" />
            <source>Max jog speed:</source>
            <translation>最大点动速度：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/envelope_dialog.py" line="124" />
            <source>Max TCP speed (moves, plans):</source>
            <translation>最大 TCP 速度（移动、计划）：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/envelope_dialog.py" line="125" />
            <source>Reduced mode jog speed:</source>
            <translation>降速模式点动速度：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/envelope_dialog.py" line="126" />
            <source>Reduced mode TCP speed:</source>
            <translation>降速模式 TCP 速度：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/envelope_dialog.py" line="148" />
            <location filename="../../ui/dialogs/envelope_dialog.py" line="186" />
            <source>zone {n}</source>
            <translation>禁区 {n}</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/envelope_dialog.py" line="165" />
            <source>{what}: '{text}' is not a number</source>
            <translation>{what}：“{text}”不是数字</translation>
        </message>
    </context>
    <context>
        <name>EventLogModel</name>
        <message>
            <location filename="../../ui/panels/event_log.py" line="121" />
            <source>Time</source>
            <translation>时间</translation>
        </message>
        <message>
            <location filename="../../ui/panels/event_log.py" line="122" />
            <source>Level</source>
            <translation>级别</translation>
        </message>
        <message>
            <location filename="../../ui/panels/event_log.py" line="123" />
            <source>Source</source>
            <translation>来源</translation>
        </message>
        <message>
            <location filename="../../ui/panels/event_log.py" line="124" />
            <source>Message</source>
            <translation>消息</translation>
        </message>
        <message>
            <location filename="../../ui/panels/event_log.py" line="127" />
            <source>Info</source>
            <translation>信息</translation>
        </message>
        <message>
            <location filename="../../ui/panels/event_log.py" line="128" />
            <source>Warning</source>
            <translation>警告</translation>
        </message>
        <message>
            <location filename="../../ui/panels/event_log.py" line="129" />
            <source>Error</source>
            <translation>错误</translation>
        </message>
    </context>
    <context>
        <name>EventLogPanel</name>
        <message>
            <location filename="../../ui/panels/event_log.py" line="322" />
            <source>Show:</source>
            <translation>显示：</translation>
        </message>
        <message>
            <location filename="../../ui/panels/event_log.py" line="323" />
            <source>All events</source>
            <translation>全部事件</translation>
        </message>
        <message>
            <location filename="../../ui/panels/event_log.py" line="324" />
            <source>Warnings and errors</source>
            <translation>警告和错误</translation>
        </message>
        <message>
            <location filename="../../ui/panels/event_log.py" line="325" />
            <source>Errors only</source>
            <translation>仅错误</translation>
        </message>
        <message>
            <location filename="../../ui/panels/event_log.py" line="326" />
            <source>Clear</source>
            <translation>清空</translation>
        </message>
        <message>
            <location filename="../../ui/panels/event_log.py" line="327" />
            <source>Export…</source>
            <translation>导出…</translation>
        </message>
        <message>
            <location filename="../../ui/panels/event_log.py" line="370" />
            <source>event log</source>
            <translation>事件日志</translation>
        </message>
        <message>
            <location filename="../../ui/panels/event_log.py" line="371" />
            <source>The event log is not saved for the next start: {why}</source>
            <translation>事件日志无法保存到下次启动：{why}</translation>
        </message>
        <message>
            <location filename="../../ui/panels/event_log.py" line="421" />
            <source>alarm</source>
            <translation>报警</translation>
        </message>
        <message>
            <location filename="../../ui/panels/event_log.py" line="418" />
            <source>Alarm raised: {name}</source>
            <translation>报警触发：{name}</translation>
        </message>
        <message>
            <location filename="../../ui/panels/event_log.py" line="418" />
            <source>Alarm cleared: {name}</source>
            <translation>报警解除：{name}</translation>
        </message>
        <message>
            <location filename="../../ui/panels/event_log.py" line="427" />
            <source>bit {n}</source>
            <translation>第 {n} 位</translation>
        </message>
        <message>
            <location filename="../../ui/panels/event_log.py" line="431" />
            <source>command</source>
            <translation>命令</translation>
        </message>
        <message>
            <location filename="../../ui/panels/event_log.py" line="463" />
            <source>link</source>
            <translation>通信链路</translation>
        </message>
        <message>
            <location filename="../../ui/panels/event_log.py" line="488" />
            <source>Export event log</source>
            <translation>导出事件日志</translation>
        </message>
        <message>
            <location filename="../../ui/panels/event_log.py" line="490" />
            <source>Text files (*.txt *.log);;All files (*)</source>
            <translation>文本文件 (*.txt *.log);;所有文件 (*)</translation>
        </message>
    </context>
    <context>
        <name>Export</name>
        <message>
            <location filename="../../ui/widgets_common.py" line="382" />
            <source>Could not write {path}: {error}</source>
            <translation>无法写入 {path}：{error}</translation>
        </message>
    </context>
    <context>
        <name>JogPanel</name>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="265" />
            <source>Base frame</source>
            <translation>基坐标系</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="266" />
            <source>User frame</source>
            <translation>用户坐标系</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="267" />
            <source>Tool frame</source>
            <translation>工具坐标系</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="268" />
            <source>Joint frame</source>
            <translation>关节坐标系</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="272" />
            <source>User no.:</source>
            <translation>用户坐标号：</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="273" />
            <source>Tool no.:</source>
            <translation>工具号：</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="263" />
            <source>Frame:</source>
            <translation>坐标系：</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="274" />
            <source>External axes</source>
            <translation>外部轴</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="368" />
            <source>HOLD TO MOVE — release to stop</source>
            <translation>按住运动 — 松开即停</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="278" />
            <source>Speed:</source>
            <translation>速度：</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="275" />
            <source>J7–J11</source>
            <translation>J7–J11</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="276" />
            <source>Touch mode: the rows show the external axes J7–J11</source>
            <translation>触屏模式：各行显示外部轴 J7–J11</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="283" />
            <source>Keyboard: click this panel, then hold {plus} (+) or {minus} (−) for axes 1–6; releasing the key stops.</source>
            <translation>键盘：先单击本面板，再按住 {plus}（+）或 {minus}（−）点动第 1–6 轴；松开按键即停止。</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="286" />
            <source>Keys: hold {plus} (+) or {minus} (−)</source>
            <translation>按键：按住 {plus} (+) 或 {minus} (−)</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="373" />
            <source>Releasing — the controller has not confirmed</source>
            <translation>正在松开 — 控制器尚未确认</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="375" />
            <source>Pausing — the controller has not confirmed; press STOP</source>
            <translation>正在暂停 — 控制器尚未确认；请按停止</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="377" />
            <source>Stopping — the controller has not confirmed</source>
            <translation>正在停止 — 控制器尚未确认</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="379" />
            <source>The controller refused or did not answer the write that stops the arm. TeachPad sends it again at every poll until the controller answers and the arm is seen still.</source>
            <translation>控制器拒绝或未应答使机械臂停止的写入。TeachPad 每次轮询都会重新发送，直到控制器应答且确认机械臂已静止。</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="384" />
            <source>The Pause was not confirmed in time: Stop was sent instead.</source>
            <translation>暂停未在时限内得到确认：已改为发送停止。</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="386" />
            <source>Stop was sent too.</source>
            <translation>也已发送停止命令。</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="527" />
            <source>°</source>
            <translation>°</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="527" />
            <source>mm</source>
            <translation>mm</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="529" />
            <source>Hold: {axis} − ({unit})</source>
            <translation>按住：{axis} −（{unit}）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="532" />
            <source>Hold: {axis} + ({unit})</source>
            <translation>按住：{axis} +（{unit}）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="546" />
            <source>{ratio} %</source>
            <translation>{ratio} %</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="551" />
            <source>{ratio} % → {cap} % (reduced speed)</source>
            <translation>{ratio} % → {cap} %（降速模式）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="553" />
            <source>{ratio} % → {cap} %</source>
            <translation>{ratio} % → {cap} %</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="558" />
            <source>Capped at {cap} % (reduced speed): the jog goes out at {cap} %, not {ratio} %</source>
            <translation>限制为 {cap} %（降速模式）：点动以 {cap} % 而不是 {ratio} % 发出</translation>
        </message>
        <message>
            <location filename="../../ui/panels/jog_panel.py" line="561" />
            <source>Capped at {cap} % (the safety envelope's maximum): the jog goes out at {cap} %, not {ratio} %</source>
            <translation>限制为 {cap} %（安全范围的最大值）：点动以 {cap} % 而不是 {ratio} % 发出</translation>
        </message>
    </context>
    <context>
        <name>JoinNames</name>
        <message>
            <location filename="../../ui/joins.py" line="20" />
            <source>, </source>
            <translation>、</translation>
        </message>
    </context>
    <context>
        <name>Joins</name>
        <message>
            <location filename="../../ui/joins.py" line="25" />
            <source>, </source>
            <translation>，</translation>
        </message>
        <message>
            <location filename="../../ui/joins.py" line="30" />
            <source>; </source>
            <translation>；</translation>
        </message>
        <message>
            <location filename="../../ui/joins.py" line="35" />
            <source>{label}: {text}</source>
            <translation>{label}：{text}</translation>
        </message>
    </context>
    <context>
        <name>KeypadDialog</name>
        <message>
            <location filename="../../ui/keypad.py" line="102" />
            <source>Enter a value</source>
            <translation>输入数值</translation>
        </message>
        <message>
            <location filename="../../ui/keypad.py" line="103" />
            <source>OK</source>
            <translation>确定</translation>
        </message>
        <message>
            <location filename="../../ui/keypad.py" line="104" />
            <source>Cancel</source>
            <translation>取消</translation>
        </message>
        <message>
            <location filename="../../ui/keypad.py" line="105" />
            <source>Delete the last digit</source>
            <translation>删除最后一位</translation>
        </message>
        <message>
            <location filename="../../ui/keypad.py" line="106" />
            <source>Clear</source>
            <translation>清空</translation>
        </message>
        <message>
            <location filename="../../ui/keypad.py" line="108" />
            <source>From {low} to {high}</source>
            <translation>范围：{low} 至 {high}</translation>
        </message>
    </context>
    <context>
        <name>LinkGuard</name>
        <message>
            <location filename="../../ui/controllers/link_guard.py" line="136" />
            <source>Disconnect</source>
            <translation>断开连接</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/link_guard.py" line="140" />
            <source>Disconnecting does not stop the robot, and TeachPad no longer shows what it does. Stop all motion first?</source>
            <translation>断开连接不会停止机器人，且 TeachPad 将不再显示它的动作。要先停止所有运动吗？</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/link_guard.py" line="144" />
            <source>Stop, then disconnect</source>
            <translation>先停止，再断开</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/link_guard.py" line="145" />
            <source>Disconnect without stopping</source>
            <translation>不停止，直接断开</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/link_guard.py" line="162" />
            <source>Close TeachPad</source>
            <translation>关闭 TeachPad</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/link_guard.py" line="163" />
            <source>Closing TeachPad does not stop the robot. Stop all motion first?</source>
            <translation>关闭 TeachPad 不会停止机器人。要先停止所有运动吗？</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/link_guard.py" line="164" />
            <source>Stop, then close</source>
            <translation>先停止，再关闭</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/link_guard.py" line="165" />
            <source>Close without stopping</source>
            <translation>不停止，直接关闭</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/link_guard.py" line="185" />
            <source>the controller</source>
            <translation>控制器</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/link_guard.py" line="187" />
            <source>Under way on {endpoint}:
{items}

{ending}</source>
            <translation>{endpoint} 上正在进行：
{items}

{ending}</translation>
        </message>
    </context>
    <context>
        <name>MainWindow</name>
        <message>
            <location filename="../../ui/window_column.py" line="116" />
            <source>Jog</source>
            <extracomment>How long the "another master" banner stays after the last sign of one (ms)</extracomment>
            <translation>点动</translation>
        </message>
        <message>
            <location filename="../../ui/window_column.py" line="117" />
            <source>Step</source>
            <translation>增量运动</translation>
        </message>
        <message>
            <location filename="../../ui/window_column.py" line="118" />
            <source>Program</source>
            <translation>程序</translation>
        </message>
        <message>
            <location filename="../../ui/window_docks.py" line="117" />
            <source>Status</source>
            <translation>状态</translation>
        </message>
        <message>
            <location filename="../../ui/window_docks.py" line="118" />
            <source>Event log</source>
            <translation>事件日志</translation>
        </message>
        <message>
            <location filename="../../ui/window_docks.py" line="119" />
            <source>Modbus traffic</source>
            <translation>Modbus 报文</translation>
        </message>
        <message>
            <location filename="../../ui/window_status.py" line="89" />
            <source>MONITOR ONLY</source>
            <translation>仅监视</translation>
        </message>
        <message>
            <location filename="../../ui/main_window.py" line="376" />
            <source>TeachPad</source>
            <translation>TeachPad 示教器</translation>
        </message>
        <message>
            <location filename="../../ui/window_column.py" line="189" />
            <source>Monitor only: motion controls are disabled</source>
            <translation>仅监视：运动控制已禁用</translation>
        </message>
        <message>
            <location filename="../../ui/window_column.py" line="193" />
            <source>Not connected: motion controls are disabled</source>
            <translation>未连接：运动控制已禁用</translation>
        </message>
        <message>
            <location filename="../../ui/window_status.py" line="53" />
            <location filename="../../ui/window_status.py" line="103" />
            <source>RTT {ms} ms</source>
            <translation>往返 {ms} ms</translation>
        </message>
        <message>
            <location filename="../../ui/window_status.py" line="68" />
            <source>Project: {name}</source>
            <translation>工程：{name}</translation>
        </message>
        <message>
            <location filename="../../ui/window_status.py" line="101" />
            <source>RTT —</source>
            <translation>往返 —</translation>
        </message>
        <message>
            <location filename="../../ui/main_window.py" line="422" />
            <source>The controller restarted (its temp points are gone): restore them from the Points tab</source>
            <translation>控制器已重启（临时点已丢失）：请在“点位”页恢复全部点</translation>
        </message>
        <message>
            <location filename="../../ui/foreign_words.py" line="25" />
            <source>it wrote its own restart token ({value})</source>
            <translation>它写入了自己的重启标记（{value}）</translation>
        </message>
        <message>
            <location filename="../../ui/foreign_words.py" line="27" />
            <source>register {value} changed without a write of TeachPad</source>
            <translation>寄存器 {value} 在 TeachPad 未写入的情况下发生了变化</translation>
        </message>
        <message>
            <location filename="../../ui/foreign_words.py" line="31" />
            <source>a command result TeachPad did not cause (GV291 = {value})</source>
            <translation>出现了并非 TeachPad 引起的指令结果（GV291 = {value}）</translation>
        </message>
        <message>
            <location filename="../../ui/foreign_words.py" line="40" />
            <source>token {value}</source>
            <translation>重启标记 {value}</translation>
        </message>
        <message>
            <location filename="../../ui/foreign_words.py" line="42" />
            <source>register {value}</source>
            <translation>寄存器 {value}</translation>
        </message>
        <message>
            <location filename="../../ui/foreign_words.py" line="44" />
            <source>GV291 = {value}</source>
            <translation>GV291 = {value}</translation>
        </message>
        <message>
            <location filename="../../ui/foreign_words.py" line="50" />
            <source>Another Modbus master is on this controller ({sign}): check who else is connected.</source>
            <translation>此控制器上还有另一个 Modbus 主站（{sign}）：请检查还有谁连接着控制器。</translation>
        </message>
        <message>
            <location filename="../../ui/foreign_words.py" line="57" />
            <source>Seen: {sign}. Another master shares the parameter and command registers with TeachPad: its writes can change what ours do.</source>
            <translation>迹象：{sign}。另一个主站与 TeachPad 共用参数和指令寄存器：它的写入可能改变我们指令的效果。</translation>
        </message>
        <message>
            <location filename="../../ui/main_window.py" line="445" />
            <source>Reconnected to the controller: jog stopped and teach mode switched off</source>
            <translation>已重新连接控制器：点动已停止，示教模式已关闭</translation>
        </message>
        <message>
            <location filename="../../ui/main_window.py" line="400" />
            <location filename="../../ui/main_window.py" line="424" />
            <location filename="../../ui/main_window.py" line="433" />
            <location filename="../../ui/main_window.py" line="446" />
            <source>link</source>
            <translation>通信</translation>
        </message>
        <message>
            <location filename="../../ui/main_window.py" line="353" />
            <source>Monitor</source>
            <translation>监视</translation>
        </message>
        <message>
            <location filename="../../ui/main_window.py" line="354" />
            <source>Points</source>
            <translation>点位</translation>
        </message>
        <message>
            <location filename="../../ui/main_window.py" line="355" />
            <source>Planner</source>
            <translation>轨迹规划</translation>
        </message>
        <message>
            <location filename="../../ui/window_docks.py" line="120" />
            <source>Alarms</source>
            <translation>报警</translation>
        </message>
        <message>
            <location filename="../../ui/main_window.py" line="440" />
            <source>plan run</source>
            <translation>计划运行</translation>
        </message>
        <message>
            <location filename="../../ui/main_window.py" line="520" />
            <source>About TeachPad</source>
            <translation>关于 TeachPad</translation>
        </message>
        <message>
            <location filename="../../ui/main_window.py" line="522" />
            <source>&lt;b&gt;TeachPad {version}&lt;/b&gt;&lt;br&gt;Desktop teach pendant for Bochuang robot controllers (Modbus TCP / RTU).&lt;br&gt;&lt;br&gt;Esc stops all motion. Jog buttons and keys move only while held.</source>
            <translation>&lt;b&gt;TeachPad {version}&lt;/b&gt;&lt;br&gt;博创机器人控制器桌面示教器（Modbus TCP / RTU）。&lt;br&gt;&lt;br&gt;按 Esc 停止所有运动。点动按钮和按键仅在按住时运动。</translation>
        </message>
        <message>
            <location filename="../../ui/main_window.py" line="535" />
            <source>Safety state (roles, envelope, audit trail), machine-wide: {folder}</source>
            <translation>安全状态（角色、安全范围、审计记录），本机共用：{folder}</translation>
        </message>
        <message>
            <location filename="../../ui/main_window.py" line="537" />
            <source>Safety state (roles, envelope), this user's: {folder}&lt;br&gt;Audit trail: {audit}</source>
            <translation>安全状态（角色、安全范围），当前用户：{folder}&lt;br&gt;审计记录：{audit}</translation>
        </message>
        <message>
            <location filename="../../ui/main_window.py" line="556" />
            <source>language</source>
            <translation>语言</translation>
        </message>
        <message>
            <location filename="../../ui/main_window.py" line="556" />
            <source>No translation file for {code}</source>
            <translation>没有 {code} 的翻译文件</translation>
        </message>
    </context>
    <context>
        <name>Messages</name>
        <message>
            <location filename="../../ui/messages.py" line="68" />
            <source>{command}: {status}.</source>
            <translation>{command}：{status}。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="69" />
            <source>{command}: done, not confirmed by the controller.</source>
            <translation>{command}：已完成，控制器未确认。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="70" />
            <source>{command}: done (the controller is now in {mode} mode).</source>
            <translation>{command}：已完成（控制器现处于{mode}模式）。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="71" />
            <source>{command} refused by the controller: {status}.</source>
            <translation>控制器拒绝了{command}：{status}。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="72" />
            <source>{command} not taken: the controller still shows “{status}” from the previous command.</source>
            <translation>{command}未被执行：控制器仍显示上一条命令的“{status}”。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="76" />
            <source>{command} ended by an alarm: {alarms}.</source>
            <translation>{command}因报警而中止：{alarms}。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="77" />
            <source>{command}: the controller did not acknowledge it within {seconds} s.</source>
            <translation>{command}：控制器在 {seconds} s 内未确认。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="80" />
            <source>{command} did not finish within {seconds} s (last status: {status}).</source>
            <translation>{command}未在 {seconds} s 内完成（最后状态：{status}）。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="83" />
            <source>{command}: the arm moved and stopped, but the controller did not report the result.</source>
            <translation>{command}：机械臂已运动并停止，但控制器未报告结果。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="86" />
            <source>{command}: stopped by the operator.</source>
            <translation>{command}：已由操作员停止。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="87" />
            <source>{command}: stopped by the controller.</source>
            <translation>{command}：已被控制器停止。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="88" />
            <source>{command}: sent (not waited for).</source>
            <translation>{command}：已发送（未等待结果）。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="89" />
            <source>{command}: no motion within {seconds} s (refused by the controller, or already there).</source>
            <translation>{command}：{seconds} s 内没有运动（被控制器拒绝，或已在目标位置）。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="93" />
            <source>{command} refused by the controller: {alarms}.</source>
            <translation>{command}被控制器拒绝：{alarms}。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="94" />
            <source>{command}: sent; the outcome is unknown — check the robot before sending it again.</source>
            <translation>{command}：已发送，结果未知——再次发送前请先检查机器人。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="97" />
            <source>{command}: done (the axes were already at zero).</source>
            <translation>{command}：完成（各轴已在零位）。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="98" />
            <source>{command}: the arm stopped before zero ({axis} at {value}).</source>
            <translation>{command}：机械臂在到达零位前停止（{axis} 位于 {value}）。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="101" />
            <source>{command} not sent: another Modbus master wrote to the controller less than {seconds} s ago and its writes could change this move. Make sure no other master is commanding the robot, then send it again.</source>
            <translation>{command}未发送：另一个 Modbus 主站在不到 {seconds} 秒前写入了控制器，它的写入可能改变这次运动。请确认没有其他主站在指挥机器人，然后再发送。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="106" />
            <source>{command} not sent: a program or motion is under way on the controller; wait for it to end, or press Stop.</source>
            <translation>{command}未发送：控制器上有程序或运动正在进行；请等待其结束，或按停止。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="110" />
            <source>{command}: the controller did not show it within {seconds} s.</source>
            <translation>{command}：控制器在 {seconds} s 内未显示该状态。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="113" />
            <source>Program {program} did not start: no such program, or the controller refused it.</source>
            <translation>程序 {program} 未启动：没有该程序，或控制器拒绝执行。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="116" />
            <source>Uploaded {uploaded} of {total} points.</source>
            <translation>已上传 {uploaded}/{total} 个点。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="118" />
            <source>{operation}: sent.</source>
            <translation>{operation}：已发送。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="119" />
            <source>{operation}: failed.</source>
            <translation>{operation}：失败。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="120" />
            <source>{operation} is still under way: wait for it or press Stop.</source>
            <translation>{operation}仍在进行：请等待其结束或按停止。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="121" />
            <source>{operation} is still under way: wait for it, cancel it or press Stop.</source>
            <translation>{operation}仍在进行：请等待其结束、取消它或按停止。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="124" />
            <source>The link is shut down: nothing was sent.</source>
            <translation>通信链路已关闭：未发送任何内容。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="125" />
            <source>Not connected to a controller: nothing was sent.</source>
            <translation>未连接控制器：未发送任何内容。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="127" />
            <source>Jog stopped: the controller is not answering (speed 0 is sent as soon as it answers).</source>
            <translation>点动已停止：控制器无应答（一旦应答即发送速度 0）。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="130" />
            <source>Jog stopped: the controller left teach mode (now in {mode} mode).</source>
            <translation>点动已停止：控制器已退出示教模式（当前为{mode}模式）。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="133" />
            <source>The controller is not answering: the jog was not started.</source>
            <translation>控制器无应答：点动未启动。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="137" />
            <source>Releasing — the controller has not confirmed: it refused or did not answer speed 0. Speed 0 is sent again at every poll until the controller answers and the arm stands still.</source>
            <translation>正在松开 — 控制器尚未确认：它拒绝或未应答速度 0。每次轮询都会重新发送速度 0，直到控制器应答且机械臂静止。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="142" />
            <source>Releasing — the controller has not confirmed speed 0 after {seconds} s: Stop is sent as well, at every poll, until the controller takes it.</source>
            <translation>正在松开 — {seconds} 秒后控制器仍未确认速度 0：每次轮询同时发送停止命令，直到控制器接受。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="147" />
            <source>Jog stopped: the controller confirmed after {seconds} s and the arm stands still.</source>
            <translation>点动已停止：控制器在 {seconds} 秒后确认，机械臂已静止。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="150" />
            <source>Stopping — the controller has not confirmed: it refused or did not answer the Stop. Stop is sent again at every poll until the controller takes it and the arm stands still.</source>
            <translation>正在停止 — 控制器尚未确认：它拒绝或未应答停止命令。每次轮询都会重新发送停止命令，直到控制器接受且机械臂静止。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="155" />
            <source>Stop confirmed by the controller after {seconds} s; the arm stands still.</source>
            <translation>控制器在 {seconds} 秒后确认停止；机械臂已静止。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="158" />
            <source>Pausing — the controller has not confirmed: it refused or did not answer the Pause; the arm may still be moving. Pause is sent again at every poll. Press STOP if it must stop now.</source>
            <translation>正在暂停 — 控制器尚未确认：它拒绝或未应答暂停；机械臂可能仍在运动。每次轮询都会重新发送暂停。如需立即停止，请按停止。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="163" />
            <source>Pause not confirmed by the controller after {seconds} s: Stop is sent instead, at every poll, until the controller takes it.</source>
            <translation>{seconds} 秒后控制器仍未确认暂停：改为在每次轮询时发送停止，直到控制器接受。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="168" />
            <source>Pause confirmed by the controller after {seconds} s: the arm is paused.</source>
            <translation>控制器在 {seconds} 秒后确认了暂停：机械臂已暂停。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="171" />
            <source>Pause not confirmed by the controller within {seconds} s: the arm was stopped (Stop) instead.</source>
            <translation>控制器在 {seconds} 秒内未确认暂停：已改为停止机械臂。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="175" />
            <source>Pause: nothing left to pause (the motion ended before the controller took the Pause).</source>
            <translation>暂停：没有可暂停的运动（运动在控制器接受暂停之前已结束）。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="178" />
            <source>Pause not confirmed by the controller: it was not sent again (Resume, Stop, another motion or a new connection came first).</source>
            <translation>控制器未确认暂停：不再重新发送（之前已有继续、停止、其他运动或新的连接）。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="183" />
            <source>{operation} refused: the controller has not confirmed that the arm stopped (the stop is sent again at every poll). Press Stop, or wait until the arm stands still.</source>
            <translation>{operation}被拒绝：控制器尚未确认机械臂已停止（每次轮询都会重新发送停止）。请按停止，或等待机械臂静止。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="188" />
            <source>The controller is not answering: the plan was not started. Try again when it answers.</source>
            <translation>控制器无应答：计划未启动。待其恢复应答后再试。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="191" />
            <source>Jog speed {value}% is not within 1..100%.</source>
            <translation>点动速度 {value}% 不在 1..100% 范围内。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="193" />
            <source>Lost the connection to the controller at {endpoint}.</source>
            <translation>与控制器 {endpoint} 的连接已断开。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="194" />
            <source>The controller at {endpoint} closed the connection.</source>
            <translation>控制器 {endpoint} 关闭了连接。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="195" />
            <source>The host name {host} cannot be resolved.</source>
            <translation>无法解析主机名 {host}。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="196" />
            <source>The host name {host} is not valid: check it in Connect…</source>
            <translation>主机名 {host} 无效：请在“连接…”中检查。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="197" />
            <source>Connection refused: nothing listens on port {port}.</source>
            <translation>连接被拒绝：端口 {port} 上没有服务在监听。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="200" />
            <source>No answer to the connection request within {seconds} s.</source>
            <translation>连接请求在 {seconds} s 内无应答。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="203" />
            <source>The connection could not be opened.</source>
            <translation>无法建立连接。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="204" />
            <source>Cannot open the serial port {port}.</source>
            <translation>无法打开串口 {port}。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="205" />
            <source>The controller at {endpoint} did not answer within {seconds} s.</source>
            <translation>控制器 {endpoint} 在 {seconds} s 内无应答。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="208" />
            <source>Malformed answer from the controller at {endpoint}: {field} expected {expected}, got {got}.</source>
            <translation>控制器 {endpoint} 的应答格式错误：{field}应为 {expected}，实际为 {got}。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="212" />
            <source>The controller refused the request: Modbus exception {exception} ({name}).</source>
            <translation>控制器拒绝了请求：Modbus 异常 {exception}（{name}）。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="217" />
            <source>Pause refused by the controller (Modbus exception {exception}, {name}): the arm was not paused. Press STOP if it must stop now, or press Pause again.</source>
            <translation>控制器拒绝了暂停（Modbus 异常 {exception}，{name}）：机械臂没有暂停。如需立即停止请按停止，或再按一次暂停。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="222" />
            <source>Resume refused by the controller (Modbus exception {exception}, {name}): the arm stays paused. Press Resume again in a moment.</source>
            <translation>控制器拒绝了继续（Modbus 异常 {exception}，{name}）：机械臂仍处于暂停。请稍后再按一次继续。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="227" />
            <source>Switch to {mode} mode refused by the controller (Modbus exception {exception}, {name}): the work mode did not change. Switch it again in a moment.</source>
            <translation>控制器拒绝了切换到{mode}模式（Modbus 异常 {exception}，{name}）：工作模式没有改变。请稍后再切换一次。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="232" />
            <source>{command} refused by the controller: Modbus exception {exception} ({name}).</source>
            <translation>控制器拒绝了{command}：Modbus 异常 {exception}（{name}）。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="236" />
            <source>No device answered at unit id {unit} (Modbus exception {exception}, {name}): check the unit id in Connect…</source>
            <translation>从站地址 {unit} 上没有设备应答（Modbus 异常 {exception}，{name}）：请在“连接…”中检查从站地址。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="240" />
            <source>Monitor-only mode: nothing was sent to the controller.</source>
            <translation>仅监视模式：未向控制器发送任何内容。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="241" />
            <source>Not sent: the audit trail in {folder} cannot be written ({cause}). No write goes out without its record (Stop still does): free disk space or fix the audit folder.</source>
            <translation>未发送：审计记录目录 {folder} 无法写入（{cause}）。没有审计记录的写入一律不发送（停止除外）：请释放磁盘空间或修复审计目录。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="246" />
            <source>{operation}: not sent, the controller is in {mode} mode. Switching it to auto is the operator's decision: say yes when the confirmation asks, or switch it to auto first.</source>
            <translation>{operation}：未发送，控制器处于{mode}模式。切换到自动模式须由操作员决定：在确认框询问时选择“是”，或先将其切换到自动模式。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="251" />
            <source>{operation}: not sent in reduced-speed mode: it runs at the controller's own speed, which TeachPad cannot cap.</source>
            <translation>{operation}：降速模式下未发送：它以控制器自身的速度运行，TeachPad 无法限制该速度。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="256" />
            <location filename="../../ui/messages_plan.py" line="29" />
            <source>Invalid value: nothing was sent.</source>
            <translation>数值无效：未发送。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="257" />
            <source>Unexpected internal error; the log has the details.</source>
            <translation>意外的内部错误；详情见日志。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="259" />
            <source>The arm stopped at ({got}), {distance} mm from {point} ({want}): the controller's copy of the point is not this project's (overwritten by another tool?). Check the point and the robot before resuming.</source>
            <translation>机械臂停在 ({got})，距 {point} ({want}) {distance} mm：控制器中的该点与本项目不一致（被其他工具改写？）。恢复运行前请检查该点和机器人。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="263" />
            <source>The controller did not create {point} again before the move: the arm was not moved.</source>
            <translation>运动前控制器未能重新创建 {point}：机械臂未移动。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="266" />
            <source>The project has no point {point}: the arm was not moved.</source>
            <translation>项目中没有点 {point}：机械臂未移动。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="269" />
            <source>The arm's position after the move to {point} is not known: the run is stopped.</source>
            <translation>移动到 {point} 后机械臂的位置未知：运行已停止。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="273" />
            <source>The link was shut down.</source>
            <translation>通信链路已关闭。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="283" />
            <source>{operation}: not sent, the connection to the controller is down.</source>
            <translation>{operation}：未发送，与控制器的连接已断开。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="286" />
            <source>{operation}: not sent, the connection was closed.</source>
            <translation>{operation}：未发送，连接已关闭。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="288" />
            <source>points outside {id_min}..{id_max}: {ids}</source>
            <translation>超出 {id_min}..{id_max} 范围的点：{ids}</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="289" />
            <source>there is no point P{id}</source>
            <translation>不存在点 P{id}</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="290" />
            <source>no free point id left in {start}..{id_max}</source>
            <translation>{start}..{id_max} 范围内已没有空闲的点编号</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="291" />
            <source>there is no row {row}</source>
            <translation>不存在第 {row} 行</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="292" />
            <source>cannot move row {src} to {dst} in {rows} rows</source>
            <translation>无法在 {rows} 行中将第 {src} 行移到第 {dst} 行</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="293" />
            <source>row {row}: id {id} is already used on row {other}</source>
            <translation>第 {row} 行：编号 {id} 已被第 {other} 行使用</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="294" />
            <source>imported point {number}: id {id} appears twice</source>
            <translation>导入的第 {number} 个点：编号 {id} 出现了两次</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="295" />
            <source>id {id} is already used by {point}</source>
            <translation>编号 {id} 已被 {point} 使用</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="296" />
            <source>the file has no points: replacing with it would remove all {existing} points of the project (merge it, or ask explicitly for an empty import)</source>
            <translation>文件中没有点：用它替换将删除工程中全部 {existing} 个点（请改用合并，或明确要求空导入）</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="29" />
            <source>{value} is not a number</source>
            <translation>{value} 不是数字</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="30" />
            <source>{value} is too large</source>
            <translation>{value} 太大</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="31" />
            <source>the value is empty</source>
            <translation>值为空</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="32" />
            <source>{value} is not a finite number</source>
            <translation>{value} 不是有限的数</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="33" />
            <source>{value} is not an integer</source>
            <translation>{value} 不是整数</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="34" />
            <source>id {value} is outside {id_min}..{id_max}</source>
            <translation>编号 {value} 超出 {id_min}..{id_max}</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="35" />
            <source>tool {value} is not 0..{max} or {none} (none)</source>
            <translation>工具 {value} 不在 0..{max} 范围内，也不是 {none}（无）</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="36" />
            <source>the value is not text</source>
            <translation>值不是文本</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="37" />
            <source>the text is longer than {max} characters</source>
            <translation>文本超过 {max} 个字符</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="38" />
            <source>holds an invalid character (a lone surrogate, not Unicode text)</source>
            <translation>含有无效字符（孤立的代理项，不是 Unicode 文本）</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="41" />
            <source>must be one line</source>
            <translation>必须为单行</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="42" />
            <source>the value is missing</source>
            <translation>缺少该值</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="44" />
            <source>not UTF-8 text (bad byte at offset {offset}); save the file as UTF-8</source>
            <translation>不是 UTF-8 文本（偏移 {offset} 处有无效字节）；请将文件另存为 UTF-8</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="47" />
            <source>the file is empty (expected a header row)</source>
            <translation>文件为空（应有表头行）</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="48" />
            <source>unknown column {name} (expected: {expected})</source>
            <translation>未知列 {name}（应为：{expected}）</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="49" />
            <source>the column appears twice</source>
            <translation>该列出现了两次</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="50" />
            <source>the column is missing from the header</source>
            <translation>表头中缺少该列</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="51" />
            <source>has {cells} cells, the header has {header} (truncated or extra cells?)</source>
            <translation>有 {cells} 个单元格，表头有 {header} 个（被截断或有多余单元格？）</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="54" />
            <source>id {id} is already used on row {other}</source>
            <translation>编号 {id} 已在第 {other} 行使用</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="274" />
            <source>{operation}: the connection was lost while it was under way; the outcome is unknown — check the robot before sending it again.</source>
            <translation>{operation}：执行期间连接中断，结果未知——再次发送前请先检查机器人。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="278" />
            <source>{operation}: the connection was closed while it was under way; the outcome is unknown — check the robot before sending it again.</source>
            <translation>{operation}：执行期间连接被关闭，结果未知——再次发送前请先检查机器人。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="307" />
            <source>No connection to the controller.</source>
            <translation>未连接控制器。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="308" />
            <source>The controller closed the connection.</source>
            <translation>控制器关闭了连接。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="309" />
            <source>Connection refused by the controller.</source>
            <translation>控制器拒绝了连接。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="310" />
            <source>The controller did not answer.</source>
            <translation>控制器无应答。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="311" />
            <source>Malformed answer from the controller.</source>
            <translation>控制器的应答格式错误。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="312" />
            <source>Cannot open the serial port.</source>
            <translation>无法打开串口。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="313" />
            <source>The host name cannot be resolved.</source>
            <translation>无法解析主机名。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="314" />
            <source>The host name is not valid.</source>
            <translation>主机名无效。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="315" />
            <source>No answer to the connection request.</source>
            <translation>连接请求无应答。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="316" />
            <source>{command} did not finish in time.</source>
            <translation>{command}未按时完成。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="317" />
            <source>{command}: the controller did not acknowledge it.</source>
            <translation>{command}：控制器未确认。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="318" />
            <source>{command} ended by an alarm.</source>
            <translation>{command}因报警而中止。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="319" />
            <location filename="../../ui/messages.py" line="339" />
            <source>{command} refused by the controller.</source>
            <translation>控制器拒绝了{command}。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="320" />
            <source>{command}: done.</source>
            <translation>{command}：已完成。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="321" />
            <source>The controller refused the request (Modbus exception).</source>
            <translation>控制器拒绝了请求（Modbus 异常）。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="324" />
            <source>{operation}: not sent, the controller is not in auto mode.</source>
            <translation>{operation}：未发送，控制器不处于自动模式。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="327" />
            <source>Pause refused by the controller: the arm was not paused. Press STOP if it must stop now, or press Pause again.</source>
            <translation>控制器拒绝了暂停：机械臂没有暂停。如需立即停止请按停止，或再按一次暂停。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="332" />
            <source>Resume refused by the controller: the arm stays paused. Press Resume again in a moment.</source>
            <translation>控制器拒绝了继续：机械臂仍处于暂停。请稍后再按一次继续。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="335" />
            <source>Work mode change refused by the controller: the work mode did not change. Switch it again in a moment.</source>
            <translation>控制器拒绝了工作模式切换：工作模式没有改变。请稍后再切换一次。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="346" />
            <source>Cannot reconnect to the controller at {endpoint}: {cause}</source>
            <translation>无法重新连接控制器 {endpoint}：{cause}</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="347" />
            <source>Cannot connect to the controller at {endpoint}: {cause}</source>
            <translation>无法连接控制器 {endpoint}：{cause}</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="348" />
            <source>The command</source>
            <translation>该命令</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="349" />
            <source>Failed.</source>
            <translation>失败。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="350" />
            <source>Failed: {message}</source>
            <translation>失败：{message}</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="353" />
            <source>stop</source>
            <translation>停止</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="354" />
            <source>pause</source>
            <translation>暂停</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="355" />
            <source>resume</source>
            <translation>继续</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="356" />
            <source>jog</source>
            <translation>点动</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="357" />
            <source>jog release</source>
            <translation>点动松开</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="358" />
            <source>jog speed</source>
            <translation>点动速度</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="359" />
            <source>incremental move</source>
            <translation>增量运动</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="360" />
            <source>work mode</source>
            <translation>工作模式</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="361" />
            <source>go to zero</source>
            <translation>回零</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="362" />
            <source>run program</source>
            <translation>运行程序</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="363" />
            <source>create temp point</source>
            <translation>创建临时点</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="364" />
            <source>move to temp point</source>
            <translation>运动至临时点</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="365" />
            <source>upload temp points</source>
            <translation>上传临时点</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="366" />
            <source>cancel upload</source>
            <translation>取消上传</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="367" />
            <source>teach disable</source>
            <translation>示教禁止</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="368" />
            <source>monitor</source>
            <translation>监视</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="369" />
            <source>connect</source>
            <translation>连接</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="370" />
            <source>disconnect</source>
            <translation>断开</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="371" />
            <source>shutdown</source>
            <translation>关闭</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="372" />
            <source>restart check</source>
            <translation>重启检测</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="373" />
            <source>read registers</source>
            <translation>读取寄存器</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="375" />
            <source>request</source>
            <translation>请求</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="378" />
            <source>length</source>
            <translation>长度</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="379" />
            <source>function code</source>
            <translation>功能码</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="380" />
            <source>byte count</source>
            <translation>字节数</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="381" />
            <source>exception code</source>
            <translation>异常码</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="382" />
            <source>address</source>
            <translation>地址</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="383" />
            <source>value</source>
            <translation>数值</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="384" />
            <source>quantity</source>
            <translation>数量</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="385" />
            <source>transaction id</source>
            <translation>事务标识</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="386" />
            <source>protocol id</source>
            <translation>协议标识</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="387" />
            <source>unit id</source>
            <translation>从站地址</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="388" />
            <source>CRC</source>
            <translation>CRC 校验</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="392" />
            <source>illegal function</source>
            <translation>非法功能</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="393" />
            <source>illegal data address</source>
            <translation>非法数据地址</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="394" />
            <source>illegal data value</source>
            <translation>非法数据值</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="395" />
            <source>server device failure</source>
            <translation>从站设备故障</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="396" />
            <source>acknowledge</source>
            <translation>已确认，处理中</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="397" />
            <source>server device busy</source>
            <translation>从站设备忙</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="398" />
            <source>negative acknowledge</source>
            <translation>否定应答</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="399" />
            <source>memory parity error</source>
            <translation>存储奇偶校验错误</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="400" />
            <source>gateway path unavailable</source>
            <translation>网关路径不可用</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="401" />
            <source>gateway target device failed to respond</source>
            <translation>网关目标设备无响应</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="403" />
            <source>unknown exception</source>
            <translation>未知异常</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="607" />
            <source>Stop sent (on the separate stop connection); the main connection did not take it: {cause}</source>
            <translation>停止已发出（经独立的停止连接）；主连接未接受：{cause}</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="610" />
            <source>Stop sent (on the separate stop connection); the main connection did not take it.</source>
            <translation>停止已发出（经独立的停止连接）；主连接未接受。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="656" />
            <source>Stop sent to {endpoint} over a fresh connection (TeachPad was not connected to it).</source>
            <translation>停止已经由新建连接发送到 {endpoint}（TeachPad 当时未与其连接）。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="659" />
            <source>Stop sent to {endpoint} over a fresh connection; the main connection did not take it: {cause}</source>
            <translation>停止已经由新建连接发送到 {endpoint}；主连接未接受：{cause}</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="663" />
            <source>Stop sent to {endpoint} over a fresh connection; the main connection did not take it.</source>
            <translation>停止已经由新建连接发送到 {endpoint}；主连接未接受。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="666" />
            <source>Stop could not reach the controller at {endpoint}: {cause} Check the robot.</source>
            <translation>停止未能送达 {endpoint} 的控制器：{cause} 请检查机器人。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="669" />
            <source>Stop could not reach the controller at {endpoint}. Check the robot.</source>
            <translation>停止未能送达 {endpoint} 的控制器。请检查机器人。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="699" />
            <source>{operation}: not sent, cancelled by Stop.</source>
            <translation>{operation}：未发送，已被停止取消。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="700" />
            <source>{operation}: not sent, the upload was cancelled.</source>
            <translation>{operation}：未发送，上传已取消。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="33" />
            <source>{where}{axis} = {value} {unit} is outside the allowed work space (limit {limit} {unit}).</source>
            <translation>{where}{axis} = {value} {unit} 超出允许的工作空间（限值 {limit} {unit}）。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="36" />
            <source>{where}the path enters the keep-out zone “{box}” ({axis} = {value} {unit}, its face is at {limit} {unit}).</source>
            <translation>{where}路径进入禁入区“{box}”（{axis} = {value} {unit}，边界位于 {limit} {unit}）。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="40" />
            <source>{where}{axis} = {value}° is past its limit {limit}°.</source>
            <translation>{where}{axis} = {value}° 超过其限位 {limit}°。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="41" />
            <source>{where}speed {value} mm/s is above the {limit} mm/s allowed.</source>
            <translation>{where}速度 {value} mm/s 超过允许的 {limit} mm/s。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="42" />
            <source>{where}jog speed {value}% is above the {limit}% allowed.</source>
            <translation>{where}点动速度 {value}% 超过允许的 {limit}%。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="43" />
            <source>{where}{axis} = {value} {unit} is within stopping distance of its limit {limit} {unit}.</source>
            <translation>{where}{axis} = {value} {unit} 已进入限值 {limit} {unit} 的停止距离内。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="47" />
            <source>Refused by the safety envelope: {text}</source>
            <translation>安全边界拒绝：{text}</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="48" />
            <source>segment {n}: </source>
            <translation>第 {n} 段：</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="49" />
            <source> (reduced-speed mode)</source>
            <translation>（减速模式）</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="616" />
            <source>The controller at {endpoint} is not answering (the connection is still open): no further segment is sent. The arm may still finish its current move; check the robot before resuming.</source>
            <translation>控制器 {endpoint} 无应答（连接仍然打开）：不再发送后续段。机械臂可能仍会完成当前的移动；恢复运行前请检查机器人。</translation>
        </message>
        <message>
            <location filename="../../ui/messages.py" line="620" />
            <source>The controller is not answering (the connection is still open): no further segment is sent. The arm may still finish its current move; check the robot before resuming.</source>
            <translation>控制器无应答（连接仍然打开）：不再发送后续段。机械臂可能仍会完成当前的移动；恢复运行前请检查机器人。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="85" />
            <source>Plan “{plan}” has no segments.</source>
            <translation>规划“{plan}”没有任何段。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="86" />
            <source>Cannot start at segment {start}: the plan has {segments} segments.</source>
            <translation>无法从第 {start} 段开始：该规划只有 {segments} 段。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="89" />
            <source>speed {speed} mm/s is not in (0, {max}] mm/s.</source>
            <translation>速度 {speed} mm/s 不在 (0, {max}] mm/s 范围内。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="90" />
            <source>the arc has no middle point.</source>
            <translation>圆弧没有中间点。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="91" />
            <source>middle point P{id} does not exist.</source>
            <translation>中间点 P{id} 不存在。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="92" />
            <source>end point P{id} does not exist.</source>
            <translation>终点 P{id} 不存在。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="93" />
            <source>{point} is not on the controller ({sync}); upload it.</source>
            <translation>{point} 不在控制器上（{sync}）；请上传。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="94" />
            <source>{point} was taught with {point_tool}, the segment moves with {segment_tool}.</source>
            <translation>{point} 示教时的工具为“{point_tool}”，该段运动的工具为“{segment_tool}”。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="97" />
            <source>the line goes nowhere (start and end {length} mm apart){where}.</source>
            <translation>直线没有移动（起点与终点相距 {length} mm）{where}。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="100" />
            <source>the arc starts at the robot's current pose, which is not known: its shape is not checked.</source>
            <translation>圆弧从机器人的当前位姿开始，但当前位姿未知：未检查其形状。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="104" />
            <source>the arc's start and middle points coincide (closer than {tolerance} mm): three distinct points are needed{where}.</source>
            <translation>圆弧的起点与中间点重合（距离小于 {tolerance} mm）：需要三个不同的点{where}。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="108" />
            <source>the arc's middle and end points coincide (closer than {tolerance} mm): three distinct points are needed{where}.</source>
            <translation>圆弧的中间点与终点重合（距离小于 {tolerance} mm）：需要三个不同的点{where}。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="112" />
            <source>the arc's start and end points coincide (closer than {tolerance} mm): three distinct points are needed{where}.</source>
            <translation>圆弧的起点与终点重合（距离小于 {tolerance} mm）：需要三个不同的点{where}。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="116" />
            <source>the arc's three points are (nearly) on one line: the middle point is {offset} mm off the start-end line (at least {tolerance} mm needed); use a line instead{where}.</source>
            <translation>圆弧的三个点（几乎）在一条直线上：中间点距起点—终点连线仅 {offset} mm（至少需要 {tolerance} mm）；请改用直线{where}。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="120" />
            <source>the arm stopped past the arc's middle point: sent from here the arc would swing {sweep}° round through the middle point (planned {planned}°); move to the end point with a line, or run from the segment before.</source>
            <translation>机械臂停在圆弧中间点之后：从此处发送，圆弧将经过中间点绕行 {sweep}°（计划 {planned}°）；请用直线移动到终点，或从前一段开始运行。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="124" />
            <source>sent from here the arc would swing {sweep}° round through the middle point (planned {planned}°); check the preview before running from here.</source>
            <translation>从此处发送，圆弧将经过中间点绕行 {sweep}°（计划 {planned}°）；从此处运行前请检查预览。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="128" />
            <source>{point} is out of the robot model's reach.</source>
            <translation>{point} 超出机器人模型的可达范围。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="129" />
            <source>the path is out of the robot model's reach.</source>
            <translation>路径超出机器人模型的可达范围。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="130" />
            <source>{point} passes a joint limit of the robot model.</source>
            <translation>{point} 会超过机器人模型的关节限位。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="131" />
            <source>the path passes a joint limit of the robot model.</source>
            <translation>路径会超过机器人模型的关节限位。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="132" />
            <source>The robot model “{model}” disagrees with the controller's pose by {distance} mm: reach checks may be wrong.</source>
            <translation>机器人模型“{model}”与控制器的位姿相差 {distance} mm：可达性检查可能有误。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="136" />
            <source>The robot model “{model}” disagrees with the controller's pose by {angle}°: reach checks may be wrong.</source>
            <translation>机器人模型“{model}”与控制器的位姿相差 {angle}°：可达性检查可能有误。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="140" />
            <source>The robot model “{model}” disagrees with the controller's pose by {distance} mm and {angle}°: reach checks may be wrong.</source>
            <translation>机器人模型“{model}”与控制器的位姿相差 {distance} mm 和 {angle}°：可达性检查可能有误。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="144" />
            <source>runs at {cap} mm/s, the reduced-speed cap (planned {speed} mm/s).</source>
            <translation>以降速模式上限 {cap} mm/s 运行（计划 {speed} mm/s）。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="148" />
            <source> (from the current pose)</source>
            <translation>（从当前位姿出发）</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="149" />
            <source> (on loops after the first, starting at the end of segment {after})</source>
            <translation>（第一轮之后的循环中，从第 {after} 段的终点出发）</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="134" />
            <source>row {row}, column '{column}': {problem}</source>
            <translation>第 {row} 行，“{column}”列：{problem}</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="136" />
            <source>column '{column}': {problem}</source>
            <translation>“{column}”列：{problem}</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="135" />
            <source>row {row}: {problem}</source>
            <translation>第 {row} 行：{problem}</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="55" />
            <source>not valid CSV (a quote is not closed, or a stray character)</source>
            <translation>不是有效的 CSV 文件（引号未闭合，或有多余字符）</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="57" />
            <source>the file is too large ({size} bytes, at most {limit})</source>
            <translation>文件过大（{size} 字节，最多 {limit}）</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="58" />
            <source>The project would be {size} bytes, more than TeachPad opens ({limit} bytes): nothing was changed or written.</source>
            <translation>项目将有 {size} 字节，超过 TeachPad 能打开的大小（{limit} 字节）：未做任何更改，也未写入文件。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="62" />
            <source>the file does not exist</source>
            <translation>文件不存在</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="63" />
            <source>is a folder, not a file</source>
            <translation>是文件夹，不是文件</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="64" />
            <source>permission denied</source>
            <translation>没有访问权限</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="65" />
            <source>the system refused the file (error {errno})</source>
            <translation>系统拒绝访问该文件（错误 {errno}）</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="67" />
            <source>not valid JSON</source>
            <translation>不是有效的 JSON</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="68" />
            <source>not valid JSON (nested too deeply)</source>
            <translation>不是有效的 JSON（嵌套层数过多）</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="69" />
            <source>not a project: expected a JSON object at the top level</source>
            <translation>不是工程文件：顶层应为 JSON 对象</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="72" />
            <source>not a TeachPad project (format {got}, expected {expected})</source>
            <translation>不是 TeachPad 工程文件（格式为 {got}，应为 {expected}）</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="75" />
            <source>version {version} is not supported (this TeachPad reads version {supported})</source>
            <translation>不支持版本 {version}（本 TeachPad 读取版本 {supported}）</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="78" />
            <source>expected {expected}, got {got}</source>
            <translation>应为{expected}，实际为 {got}</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="79" />
            <source>id {id} is already used by point {other_number}</source>
            <translation>编号 {id} 已被第 {other_number} 个点使用</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="80" />
            <source>another plan is named “{name}”</source>
            <translation>已有另一个名为“{name}”的轨迹</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="82" />
            <source>{value} is not yes or no</source>
            <translation>{value} 不是“是”或“否”</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="83" />
            <source>{value} is not a line or an arc</source>
            <translation>{value} 不是直线或圆弧</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="84" />
            <source>{value} is not “changes” or “kept”</source>
            <translation>{value} 不是“变化”或“保持”</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="87" />
            <source>point id {id} is negative</source>
            <translation>点编号 {id} 为负数</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="88" />
            <source>there is no field “{name}”</source>
            <translation>没有字段“{name}”</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="89" />
            <source>a plan needs a name</source>
            <translation>轨迹需要一个名称</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="90" />
            <source>the name must be one line of at most {max} characters</source>
            <translation>名称必须为单行，最多 {max} 个字符</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="93" />
            <source>{value} loops: give 0 (endless) to {max}</source>
            <translation>循环次数 {value} 无效：请输入 0（无限）到 {max}</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="94" />
            <source>cannot move segment {src} to {dst} in {segments} segments</source>
            <translation>无法在 {segments} 段中把第 {src} 段移到第 {dst} 段</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="97" />
            <source>an arc needs its middle point</source>
            <translation>圆弧需要中间点</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="98" />
            <source>a line has no middle point</source>
            <translation>直线没有中间点</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="99" />
            <source>point P{id} does not exist: pick one of the list</source>
            <translation>点 P{id} 不存在：请从列表中选择</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="102" />
            <source>{speed} mm/s: the speed must be above 0</source>
            <translation>{speed} mm/s：速度必须大于 0</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="103" />
            <source>an arc's middle point must differ from its end point</source>
            <translation>圆弧的中间点必须与终点不同</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="108" />
            <source>text</source>
            <translation>文本</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="109" />
            <source>a list of points</source>
            <translation>点列表</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="110" />
            <source>a list of plans</source>
            <translation>轨迹列表</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="111" />
            <source>a list of segments</source>
            <translation>段列表</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="112" />
            <location filename="../../ui/messages_files.py" line="117" />
            <source>an object</source>
            <translation>对象</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="113" />
            <source>an object with time and endpoint</source>
            <translation>包含时间和端点的对象</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="116" />
            <source>a list</source>
            <translation>列表</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="122" />
            <source>the file</source>
            <translation>文件</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="123" />
            <source>point {number}</source>
            <translation>第 {number} 个点</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="124" />
            <source>point {number} (id {id})</source>
            <translation>第 {number} 个点（编号 {id}）</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="125" />
            <source>point {number} (id {id}), upload history</source>
            <translation>第 {number} 个点（编号 {id}）的上传记录</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="126" />
            <source>plan {number}</source>
            <translation>第 {number} 条轨迹</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="127" />
            <source>plan {number} “{name}”</source>
            <translation>第 {number} 条轨迹“{name}”</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="128" />
            <source>plan {number} “{name}”, segment {segment}</source>
            <translation>第 {number} 条轨迹“{name}”第 {segment} 段</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="129" />
            <source>line {line}, column {column}</source>
            <translation>第 {line} 行第 {column} 列</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="130" />
            <source>at “{path}”</source>
            <translation>位于“{path}”</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="131" />
            <source>a key at “{path}”</source>
            <translation>位于“{path}”的键</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="137" />
            <source>{place}, field '{column}': {problem}</source>
            <translation>{place}，字段“{column}”：{problem}</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="138" />
            <source>{place}: {problem}</source>
            <translation>{place}：{problem}</translation>
        </message>
        <message>
            <location filename="../../ui/messages_files.py" line="139" />
            <source>{file}: {text}</source>
            <translation>{file}：{text}</translation>
        </message>
        <message>
            <location filename="../../ui/messages_watch.py" line="14" />
            <source>Unknown type “{type}”: use float32, int16 or bits.</source>
            <translation>未知类型“{type}”：可用的类型为 32 位浮点数、16 位整数或 16 位的位。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_watch.py" line="17" />
            <source>Unknown source “{source}”: use gv or reg.</source>
            <translation>未知来源“{source}”：可用 GV 或寄存器。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_watch.py" line="18" />
            <source>“{text}” is not a GV or register number.</source>
            <translation>“{text}”不是 GV 或寄存器编号。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_watch.py" line="19" />
            <source>GV{value} is out of range (GV0..GV{max}).</source>
            <translation>GV{value} 超出范围（GV0..GV{max}）。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_watch.py" line="20" />
            <source>Register {value} is out of range (0..{max} for this type).</source>
            <translation>寄存器 {value} 超出范围（此类型为 0..{max}）。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_watch.py" line="23" />
            <source>A watched value's name is one line of at most {max} characters.</source>
            <translation>监视值的名称只能是一行，最多 {max} 个字符。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_watch.py" line="26" />
            <source>{name}: “{text}” is not a number.</source>
            <translation>{name}：“{text}”不是数字。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_watch.py" line="27" />
            <source>{name}: the value must be a finite number (not NaN).</source>
            <translation>{name}：数值必须是有限数（不能是非数值）。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_watch.py" line="28" />
            <source>{name}: {value} is out of range ({min}..{max}).</source>
            <translation>{name}：{value} 超出范围（{min}..{max}）。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_watch.py" line="31" />
            <source>{what}: registers 440..445 are the controller's commands; use the motion controls.</source>
            <translation>{what}：寄存器 440..445 是控制器的命令寄存器；请使用运动控制按钮。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_watch.py" line="34" />
            <source>{what} = {value}: written.</source>
            <translation>{what} = {value}：已写入。</translation>
        </message>
    </context>
    <context>
        <name>MonitorPanel</name>
        <message>
            <location filename="../../ui/panels/monitor_panel.py" line="201" />
            <location filename="../../ui/panels/monitor_panel.py" line="221" />
            <source>mm</source>
            <extracomment>Attributes that exist once the plots are built (asking for one builds them).</extracomment>
            <translation>mm</translation>
        </message>
        <message>
            <location filename="../../ui/panels/monitor_panel.py" line="201" />
            <location filename="../../ui/panels/monitor_panel.py" line="221" />
            <source>°</source>
            <translation>°</translation>
        </message>
        <message>
            <location filename="../../ui/panels/monitor_panel.py" line="202" />
            <source>TCP position (base frame)</source>
            <translation>TCP 位置（基坐标系）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/monitor_panel.py" line="204" />
            <source>Joints and external axes (°)</source>
            <translation>关节与附加轴（°）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/monitor_panel.py" line="208" />
            <source>{n} s</source>
            <translation>{n} 秒</translation>
        </message>
        <message>
            <location filename="../../ui/panels/monitor_panel.py" line="209" />
            <source>Time span of the position plots</source>
            <translation>位置曲线的时间范围</translation>
        </message>
        <message>
            <location filename="../../ui/panels/monitor_panel.py" line="210" />
            <source>Window:</source>
            <translation>时间窗：</translation>
        </message>
        <message>
            <location filename="../../ui/panels/monitor_panel.py" line="211" />
            <source>Pause plots</source>
            <translation>暂停曲线</translation>
        </message>
        <message>
            <location filename="../../ui/panels/monitor_panel.py" line="212" />
            <source>Freeze the plots; samples keep being recorded</source>
            <translation>冻结曲线；采样继续记录</translation>
        </message>
        <message>
            <location filename="../../ui/panels/monitor_panel.py" line="213" />
            <source>Clear trace</source>
            <translation>清除轨迹</translation>
        </message>
        <message>
            <location filename="../../ui/panels/monitor_panel.py" line="214" />
            <source>Erase the X–Y path trace</source>
            <translation>清除 X–Y 平面轨迹</translation>
        </message>
        <message>
            <location filename="../../ui/panels/monitor_panel.py" line="222" />
            <source>position</source>
            <translation>位置</translation>
        </message>
        <message>
            <location filename="../../ui/panels/monitor_panel.py" line="223" />
            <source>orientation</source>
            <translation>姿态</translation>
        </message>
        <message>
            <location filename="../../ui/panels/monitor_panel.py" line="224" />
            <source>time</source>
            <translation>时间</translation>
        </message>
        <message>
            <location filename="../../ui/panels/monitor_panel.py" line="224" />
            <source>s</source>
            <translation>s</translation>
        </message>
        <message>
            <location filename="../../ui/panels/monitor_panel.py" line="225" />
            <source>Top view (X–Y)</source>
            <translation>俯视图（X–Y）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/monitor_panel.py" line="244" />
            <source>Stale: not confirmed by the controller within the freshness limit</source>
            <translation>数据过期：未在时效内得到控制器确认</translation>
        </message>
        <message>
            <location filename="../../ui/panels/monitor_panel.py" line="443" />
            <source>values stale (grey): no fresh data from the controller</source>
            <translation>数值已过期（灰色）：控制器无新数据</translation>
        </message>
        <message>
            <location filename="../../ui/panels/monitor_panel.py" line="456" />
            <source>Last stop: not measured yet</source>
            <translation>上次停止：尚未测量</translation>
        </message>
        <message>
            <location filename="../../ui/panels/monitor_panel.py" line="458" />
            <source>Last stop:</source>
            <translation>上次停止：</translation>
        </message>
        <message>
            <location filename="../../ui/panels/monitor_panel.py" line="458" />
            <source>Last jog release:</source>
            <translation>上次点动松开：</translation>
        </message>
        <message>
            <location filename="../../ui/panels/monitor_panel.py" line="460" />
            <source>{ms} ms, {mm} mm</source>
            <translation>{ms} ms，{mm} mm</translation>
        </message>
        <message>
            <location filename="../../ui/panels/monitor_panel.py" line="462" />
            <source>not seen still within {s} s ({mm} mm)</source>
            <translation>{s} 秒内未见静止（{mm} mm）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/monitor_panel.py" line="469" />
            <source>Measured stopping: from the click on Stop (or a jog's release) to the arm seen still (two polls alike), and the distance it travelled meanwhile. {n} measured in this session.</source>
            <translation>停止测量：从点击停止（或松开点动）到看到机械臂静止（两次轮询相同）的时间，以及其间移动的距离。本次会话已测量 {n} 次。</translation>
        </message>
        <message>
            <location filename="../../ui/panels/monitor_panel.py" line="439" />
            <source>Plots: last {n} s</source>
            <translation>曲线：最近 {n} 秒</translation>
        </message>
        <message>
            <location filename="../../ui/panels/monitor_panel.py" line="441" />
            <source>paused</source>
            <translation>已暂停</translation>
        </message>
    </context>
    <context>
        <name>Panels</name>
        <message>
            <location filename="../../ui/widgets_common.py" line="333" />
            <source>connected</source>
            <translation>已连接</translation>
        </message>
        <message>
            <location filename="../../ui/widgets_common.py" line="334" />
            <source>connecting</source>
            <translation>正在连接</translation>
        </message>
        <message>
            <location filename="../../ui/widgets_common.py" line="337" />
            <source>disconnected</source>
            <translation>未连接</translation>
        </message>
        <message>
            <location filename="../../ui/widgets_common.py" line="336" />
            <source>link down</source>
            <translation>链路中断</translation>
        </message>
        <message>
            <location filename="../../ui/widgets_common.py" line="361" />
            <source>failed</source>
            <translation>失败</translation>
        </message>
        <message>
            <location filename="../../ui/widgets_common.py" line="352" />
            <source>command</source>
            <translation>命令</translation>
        </message>
        <message>
            <location filename="../../ui/widgets_common.py" line="335" />
            <source>not answering</source>
            <translation>无应答</translation>
        </message>
        <message>
            <location filename="../../ui/widgets_common.py" line="360" />
            <source>done</source>
            <translation>完成</translation>
        </message>
    </context>
    <context>
        <name>PasswordDialog</name>
        <message>
            <location filename="../../ui/dialogs/password_dialog.py" line="104" />
            <source>Passwords and lock</source>
            <translation>密码与锁定</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/password_dialog.py" line="105" />
            <source>Role</source>
            <translation>角色</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/password_dialog.py" line="105" />
            <source>Password</source>
            <translation>密码</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/password_dialog.py" line="106" />
            <source>New password:</source>
            <translation>新密码：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/password_dialog.py" line="107" />
            <source>Repeat:</source>
            <translation>再次输入：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/password_dialog.py" line="108" />
            <source>Set / change password</source>
            <translation>设置/修改密码</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/password_dialog.py" line="109" />
            <source>Clear password</source>
            <translation>清除密码</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/password_dialog.py" line="110" />
            <source>Lock back to operator after:</source>
            <translation>空闲多久后退回操作员：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/password_dialog.py" line="111" />
            <source> min</source>
            <translation> 分钟</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/password_dialog.py" line="123" />
            <source>not needed (the pendant starts as operator)</source>
            <translation>不需要（示教器以操作员身份启动）</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/password_dialog.py" line="125" />
            <source>set</source>
            <translation>已设置</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/password_dialog.py" line="127" />
            <source>not set (nobody can log in as this role)</source>
            <translation>未设置（无人能以此角色登录）</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/password_dialog.py" line="157" />
            <source>The administrator password can be changed, not removed</source>
            <translation>管理员密码只能修改，不能清除</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/password_dialog.py" line="171" />
            <source>The two passwords differ</source>
            <translation>两次输入的密码不一致</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/password_dialog.py" line="179" />
            <source>Not set: {why}</source>
            <translation>未设置：{why}</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/password_dialog.py" line="184" />
            <source>Password set for the {role} role</source>
            <translation>已为{role}角色设置密码</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/password_dialog.py" line="197" />
            <source>Not cleared: {why}</source>
            <translation>未清除：{why}</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/password_dialog.py" line="199" />
            <source>Password cleared for the {role} role</source>
            <translation>已清除{role}角色的密码</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/password_dialog.py" line="211" />
            <source>The setting could not be saved: {why}</source>
            <translation>设置无法保存：{why}</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/password_dialog.py" line="213" />
            <source>The window locks back to operator after {n} min without input</source>
            <translation>无操作 {n} 分钟后窗口退回操作员</translation>
        </message>
    </context>
    <context>
        <name>Plan</name>
        <message>
            <location filename="../../app/plan/segments.py" line="56" />
            <source>line</source>
            <extracomment>Editable fields of a segment, in table column order.</extracomment>
            <translation>直线</translation>
        </message>
        <message>
            <location filename="../../app/plan/segments.py" line="57" />
            <source>arc</source>
            <translation>圆弧</translation>
        </message>
    </context>
    <context>
        <name>PlanChecksBar</name>
        <message>
            <location filename="../../ui/panels/planner_widgets.py" line="269" />
            <source>Upload now</source>
            <translation>立即上传</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_widgets.py" line="270" />
            <source>Check</source>
            <translation>检查</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_widgets.py" line="279" />
            <source>Checks passed; the plan cannot run until the emergency stop or servo alarm is cleared</source>
            <translation>检查通过；急停或伺服报警解除之前，计划不能运行</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_widgets.py" line="295" />
            <source>Checks passed: ready to run</source>
            <translation>检查通过：可以运行</translation>
        </message>
        <message numerus="yes">
            <location filename="../../ui/panels/planner_widgets.py" line="298" />
            <source>%n error(s)</source>
            <translation>
                <numerusform>%n 个错误</numerusform>
            </translation>
        </message>
        <message numerus="yes">
            <location filename="../../ui/panels/planner_widgets.py" line="300" />
            <source>%n point(s) need upload</source>
            <translation>
                <numerusform>%n 个点需要上传</numerusform>
            </translation>
        </message>
        <message numerus="yes">
            <location filename="../../ui/panels/planner_widgets.py" line="302" />
            <source>%n warning(s)</source>
            <translation>
                <numerusform>%n 个警告</numerusform>
            </translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_widgets.py" line="305" />
            <source>Upload now?</source>
            <translation>立即上传？</translation>
        </message>
    </context>
    <context>
        <name>PlanEdits</name>
        <message>
            <location filename="../../ui/panels/planner_edit.py" line="94" />
            <source>Deleted plan {name} (Ctrl+Z to undo)</source>
            <translation>已删除轨迹 {name}（Ctrl+Z 撤销）</translation>
        </message>
    </context>
    <context>
        <name>PlanListBox</name>
        <message>
            <location filename="../../ui/panels/planner_widgets.py" line="339" />
            <source>Plans</source>
            <translation>轨迹规划</translation>
        </message>
    </context>
    <context>
        <name>PlanListModel</name>
        <message>
            <location filename="../../ui/models/plan_model.py" line="104" />
            <source>Plan</source>
            <translation>轨迹</translation>
        </message>
        <message>
            <location filename="../../ui/models/plan_model.py" line="104" />
            <source>Loops</source>
            <translation>循环次数</translation>
        </message>
        <message>
            <location filename="../../ui/models/plan_model.py" line="104" />
            <source>Segments</source>
            <translation>段数</translation>
        </message>
        <message>
            <location filename="../../ui/models/plan_model.py" line="157" />
            <source>endless</source>
            <translation>无限循环</translation>
        </message>
        <message>
            <location filename="../../ui/models/plan_model.py" line="161" />
            <source>How many times the plan runs (0 = until stopped)</source>
            <translation>轨迹运行次数（0 = 直到停止）</translation>
        </message>
        <message>
            <location filename="../../ui/models/plan_model.py" line="186" />
            <source>Plan: refused, {reason}</source>
            <translation>轨迹：输入被拒绝，{reason}</translation>
        </message>
        <message>
            <location filename="../../ui/models/plan_model.py" line="192" />
            <source>plan</source>
            <translation>轨迹</translation>
        </message>
        <message>
            <location filename="../../ui/models/plan_model.py" line="196" />
            <source>Add plan {name}</source>
            <translation>添加轨迹 {name}</translation>
        </message>
        <message>
            <location filename="../../ui/models/plan_model.py" line="204" />
            <source>Duplicate plan {name}</source>
            <translation>复制轨迹 {name}</translation>
        </message>
        <message>
            <location filename="../../ui/models/plan_model.py" line="210" />
            <source>Delete plan {name}</source>
            <translation>删除轨迹 {name}</translation>
        </message>
        <message>
            <location filename="../../ui/models/plan_model.py" line="220" />
            <source>Rename plan {old} to {new}</source>
            <translation>将轨迹 {old} 重命名为 {new}</translation>
        </message>
        <message>
            <location filename="../../ui/models/plan_model.py" line="229" />
            <source>Set loops of {name} to {n}</source>
            <translation>将轨迹 {name} 的循环次数设为 {n}</translation>
        </message>
    </context>
    <context>
        <name>PlanPreview</name>
        <message>
            <location filename="../../ui/panels/plan_preview.py" line="253" />
            <source>Top (XY)</source>
            <extracomment>px: a narrower preview shows one projection at a time (its tabs), the lengths / times below it (key, horizontal axis, vertical axis) — 0 = X, 1 = Y, 2 = Z.</extracomment>
            <translation>俯视（XY）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/plan_preview.py" line="254" />
            <source>Front (XZ)</source>
            <translation>正视（XZ）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/plan_preview.py" line="255" />
            <source>Side (YZ)</source>
            <translation>侧视（YZ）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/plan_preview.py" line="260" />
            <source>Top</source>
            <translation>俯视</translation>
        </message>
        <message>
            <location filename="../../ui/panels/plan_preview.py" line="261" />
            <source>Front</source>
            <translation>正视</translation>
        </message>
        <message>
            <location filename="../../ui/panels/plan_preview.py" line="262" />
            <source>Side</source>
            <translation>侧视</translation>
        </message>
        <message>
            <location filename="../../ui/panels/plan_preview.py" line="267" />
            <source>Fit</source>
            <translation>适应</translation>
        </message>
        <message>
            <location filename="../../ui/panels/plan_preview.py" line="270" />
            <source>Fit the views to the plan; they follow every change again until you zoom or pan</source>
            <translation>使视图适应整个计划；之后每次修改都会重新适应，直到您缩放或平移</translation>
        </message>
        <message>
            <location filename="../../ui/panels/plan_preview.py" line="329" />
            <source>Reach: robot model “%1”</source>
            <translation>可达性：机器人模型“%1”</translation>
        </message>
        <message>
            <location filename="../../ui/panels/plan_preview.py" line="400" />
            <source>endless</source>
            <translation>无限循环</translation>
        </message>
        <message>
            <location filename="../../ui/panels/plan_preview.py" line="401" />
            <source>&lt;b&gt;{name}&lt;/b&gt;: {n} segments, loops: {loops}</source>
            <translation>&lt;b&gt;{name}&lt;/b&gt;：{n} 段，循环次数：{loops}</translation>
        </message>
        <message>
            <location filename="../../ui/panels/plan_preview.py" line="405" />
            <source>One loop: {length}, {time}</source>
            <translation>单次循环：{length}，{time}</translation>
        </message>
        <message>
            <location filename="../../ui/panels/plan_preview.py" line="406" />
            <source>Total: {length}, {time}</source>
            <translation>合计：{length}，{time}</translation>
        </message>
        <message>
            <location filename="../../ui/panels/plan_preview.py" line="410" />
            <source>Not counted (unknown length): segments {list}</source>
            <translation>未计入（长度未知）：第 {list} 段</translation>
        </message>
        <message>
            <location filename="../../ui/panels/plan_preview.py" line="418" />
            <source>Segment {k}: {length}, {time}</source>
            <translation>第 {k} 段：{length}，{time}</translation>
        </message>
        <message>
            <location filename="../../ui/panels/plan_preview.py" line="421" />
            <source>Start: end of the last segment (robot pose unknown)</source>
            <translation>起点：最后一段的终点（机器人位姿未知）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/plan_preview.py" line="423" />
            <source>Start: the robot's current pose</source>
            <translation>起点：机器人当前位姿</translation>
        </message>
    </context>
    <context>
        <name>PlanRunBox</name>
        <message>
            <location filename="../../ui/panels/planner_widgets.py" line="212" />
            <source>endless</source>
            <extracomment>Colour of a summary line by level (the status line uses the darker warning text).</extracomment>
            <translation>无限循环</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_widgets.py" line="214" />
            <source>Segment {k} of {n}, loop {i} of {m}</source>
            <translation>第 {k}/{n} 段，第 {i}/{m} 次循环</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_widgets.py" line="235" />
            <source>Finished: {n} segments run</source>
            <translation>已完成：运行了 {n} 段</translation>
        </message>
    </context>
    <context>
        <name>PlanRunController</name>
        <message>
            <location filename="../../ui/controllers/plan_run_reasons.py" line="51" />
            <source>Failed: {reason}</source>
            <translation>失败：{reason}</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/plan_run_reasons.py" line="53" />
            <source>Stopped: {reason}</source>
            <translation>已停止：{reason}</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/plan_run_reasons.py" line="57" />
            <source>Failed at segment {n}: {reason}</source>
            <translation>在第 {n} 段失败：{reason}</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/plan_run_reasons.py" line="59" />
            <source>Stopped at segment {n}: {reason}</source>
            <translation>在第 {n} 段停止：{reason}</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/plan_run_reasons.py" line="70" />
            <source>Stopped by the operator at segment {n}</source>
            <translation>已由操作员在第 {n} 段停止</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/plan_run_reasons.py" line="74" />
            <source>Stopped by the operator at segment {n}, loop {loop} (endless)</source>
            <translation>已由操作员在第 {n} 段、第 {loop} 轮（无限循环）停止</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/plan_run_reasons.py" line="77" />
            <source>Stopped by the operator at segment {n}, loop {loop} of {loops}</source>
            <translation>已由操作员在第 {n} 段、第 {loop} 轮（共 {loops} 轮）停止</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/plan_run_reasons.py" line="97" />
            <source>Paused: another master wrote to the controller ({sign})</source>
            <translation>已暂停：另一个主站写入了控制器（{sign}）</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/plan_run_reasons.py" line="104" />
            <source>Not resumed: another master wrote to the controller less than {hold} s ago. Make sure no other master is commanding the robot; Resume is possible in {left} s.</source>
            <translation>未继续：另一个主站在不到 {hold} 秒前写入了控制器。请确认没有其他主站在控制机器人；{left} 秒后才能继续。</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/plan_run_reasons.py" line="36" />
            <source>stopped by the operator</source>
            <translation>已由操作员停止</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/plan_run_controller.py" line="705" />
            <source>the controller did not confirm the Pause in time: Stop was sent instead</source>
            <extracomment>How many of the segments sent a run remembers (``sent_segments``): a run with endless loops sends segments for as long as it runs.</extracomment>
            <translation>控制器未在时限内确认暂停：已改为发送停止</translation>
        </message>
    </context>
    <context>
        <name>PlanRunFlow</name>
        <message>
            <location filename="../../ui/panels/planner_run.py" line="79" />
            <source>The plan has no segments</source>
            <translation>轨迹没有任何段</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_run.py" line="82" />
            <source>Wait until the point upload or move ends</source>
            <translation>请等待点的上传或运动结束</translation>
        </message>
        <message numerus="yes">
            <location filename="../../ui/panels/planner_run.py" line="107" />
            <source>Cannot run: the plan has %n error(s); the first: {message}</source>
            <translation>
                <numerusform>无法运行：计划有 %n 个错误，第一个：{message}</numerusform>
            </translation>
        </message>
        <message numerus="yes">
            <location filename="../../ui/panels/planner_run.py" line="116" />
            <source>Cannot run: %n point(s) need upload</source>
            <translation>
                <numerusform>无法运行：%n 个点需要上传</numerusform>
            </translation>
        </message>
        <message numerus="yes">
            <location filename="../../ui/panels/planner_run.py" line="118" />
            <source>%n point(s) of the plan are not on the controller: </source>
            <translation>
                <numerusform>轨迹中有 %n 个点不在控制器上：</numerusform>
            </translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_run.py" line="120" />
            <source>Upload now, then run?</source>
            <translation>立即上传后运行？</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_run.py" line="121" />
            <source>Upload points</source>
            <translation>上传点</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_run.py" line="133" />
            <source>Resume plan '{name}' from segment {k}?</source>
            <translation>从第 {k} 段继续运行轨迹“{name}”？</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_run.py" line="135" />
            <source>Run segment {k} of plan '{name}' (one step)?</source>
            <translation>单步运行轨迹“{name}”的第 {k} 段？</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_run.py" line="137" />
            <source>Run plan '{name}' from segment {k}?</source>
            <translation>从第 {k} 段开始运行轨迹“{name}”？</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_run.py" line="139" />
            <source>Run plan '{name}'?</source>
            <translation>运行轨迹“{name}”？</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_run.py" line="140" />
            <source>The robot will move.</source>
            <translation>机器人将会运动。</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_run.py" line="143" />
            <source>Warnings:</source>
            <translation>警告：</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_run.py" line="147" />
            <source>Run plan</source>
            <translation>运行轨迹</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_run.py" line="178" />
            <source>Pausing… (waiting for the controller to confirm the Pause)</source>
            <translation>正在暂停…（等待控制器确认暂停）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_run.py" line="181" />
            <source>Pausing — the controller has not confirmed: the arm may still be moving. Pause is sent again at every poll. Press STOP if it must stop now.</source>
            <translation>正在暂停 — 控制器尚未确认：机械臂可能仍在运动。每次轮询都会重新发送暂停。如需立即停止，请按停止。</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_run.py" line="186" />
            <source>Pause not confirmed by the controller in time: Stop is sent instead, at every poll, until the controller takes it.</source>
            <translation>控制器未在时限内确认暂停：改为在每次轮询时发送停止，直到控制器接受。</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_run.py" line="190" />
            <source>Paused (confirmed by the controller). Press Resume to go on.</source>
            <translation>已暂停（控制器已确认）。按继续以继续运行。</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_run.py" line="193" />
            <source>Pause refused by the controller: the arm was not paused. Press STOP if it must stop now, or press Pause again.</source>
            <translation>控制器拒绝了暂停：机械臂未暂停。如需立即停止，请按停止，或再次按暂停。</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_run.py" line="227" />
            <source>The upload did not complete: the plan was not started</source>
            <translation>上传未完成：轨迹未启动</translation>
        </message>
    </context>
    <context>
        <name>PlannerActions</name>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="76" />
            <source>Add</source>
            <extracomment>The plan edits (engineer and up); the rest (run, step, pause, ...) is the operator's.</extracomment>
            <translation>添加</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="76" />
            <source>Add an empty plan</source>
            <translation>添加空轨迹</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="77" />
            <source>Rename</source>
            <translation>重命名</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="77" />
            <source>Rename the selected plan (F2)</source>
            <translation>重命名所选轨迹（F2）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="78" />
            <source>Duplicate</source>
            <translation>复制</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="78" />
            <source>Copy the selected plan</source>
            <translation>复制所选轨迹</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="79" />
            <location filename="../../ui/panels/planner_actions.py" line="82" />
            <source>Delete</source>
            <translation>删除</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="79" />
            <source>Delete the selected plan (Ctrl+Z to undo)</source>
            <translation>删除所选轨迹（Ctrl+Z 撤销）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="80" />
            <source>+ Line</source>
            <translation>+ 直线</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="80" />
            <source>Add a line segment after the selection (Ctrl+L)</source>
            <translation>在所选段之后添加直线段（Ctrl+L）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="81" />
            <source>+ Arc</source>
            <translation>+ 圆弧</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="81" />
            <source>Add an arc segment after the selection</source>
            <translation>在所选段之后添加圆弧段</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="82" />
            <source>Delete the selected segments</source>
            <translation>删除所选段</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="83" />
            <source>Move the selected segments up (Alt+Up)</source>
            <translation>上移所选段（Alt+↑）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="84" />
            <source>Move the selected segments down (Alt+Down)</source>
            <translation>下移所选段（Alt+↓）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="85" />
            <source>Check</source>
            <translation>检查</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="85" />
            <source>Check the plan from the robot's current pose</source>
            <translation>以机器人当前位姿检查轨迹</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="86" />
            <source>Upload now</source>
            <translation>立即上传</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="86" />
            <source>Upload the points the plan needs</source>
            <translation>上传轨迹所需的点</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="87" />
            <source>Run</source>
            <translation>运行</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="87" />
            <source>Run the plan from the first segment (F5)</source>
            <translation>从第一段开始运行轨迹（F5）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="88" />
            <source>Run from here</source>
            <translation>从此处运行</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="88" />
            <source>Run from the selected segment (Shift+F5)</source>
            <translation>从所选段开始运行（Shift+F5）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="89" />
            <source>Step</source>
            <translation>单步</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="89" />
            <source>Run one segment, then stop (F10)</source>
            <translation>运行一段后停止（F10）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="90" />
            <source>Pause</source>
            <translation>暂停</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="90" />
            <source>Pause the motion</source>
            <translation>暂停运动</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="91" />
            <source>Resume</source>
            <translation>继续</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="91" />
            <source>Resume the paused motion</source>
            <translation>继续已暂停的运动</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="92" />
            <source>Stop</source>
            <translation>停止</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="92" />
            <source>Stop the robot and the run</source>
            <translation>停止机器人和轨迹运行</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="93" />
            <location filename="../../ui/panels/planner_actions.py" line="106" />
            <source>Resume from segment</source>
            <translation>从该段继续</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="93" />
            <source>Continue the stopped run</source>
            <translation>继续已停止的运行</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="108" />
            <source>Resume from segment {k}</source>
            <translation>从第 {k} 段继续</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="110" />
            <source>Resume from segment {k}, loop {loop}</source>
            <translation>从第 {k} 段、第 {loop} 轮继续</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="144" />
            <source>Run is disabled: the plan's checks found errors; fix them first</source>
            <translation>无法运行：计划检查发现错误，请先修正</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="148" />
            <source>Run is disabled: not connected to the controller</source>
            <translation>无法运行：未连接控制器</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="149" />
            <source>Run is disabled: a run is going</source>
            <translation>无法运行：正在运行中</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="150" />
            <source>Run is disabled: the plan has no segments</source>
            <translation>无法运行：计划没有任何段</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_actions.py" line="151" />
            <source>Run is disabled: wait for the points' upload to finish</source>
            <translation>无法运行：请等待点位上传完成</translation>
        </message>
    </context>
    <context>
        <name>PlannerLayout</name>
        <message>
            <location filename="../../ui/panels/planner_layout.py" line="82" />
            <source>Plans</source>
            <translation>轨迹列表</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_layout.py" line="83" />
            <source>Show or hide the list of plans</source>
            <translation>显示或隐藏轨迹列表</translation>
        </message>
    </context>
    <context>
        <name>PlannerPanel</name>
        <message>
            <location filename="../../ui/panels/planner_panel.py" line="364" />
            <source>This cell cannot be edited: {why}</source>
            <translation>无法编辑此单元格：{why}</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_panel.py" line="472" />
            <source>Plan finished</source>
            <translation>轨迹运行完成</translation>
        </message>
    </context>
    <context>
        <name>PointPicker</name>
        <message>
            <location filename="../../ui/widgets/point_picker.py" line="121" />
            <source>Point P{id} does not exist</source>
            <translation>点 P{id} 不存在</translation>
        </message>
        <message>
            <location filename="../../ui/widgets/point_picker.py" line="123" />
            <source>Pick an existing point (type its id or part of its name)</source>
            <translation>请选择已有的点（输入编号或名称的一部分）</translation>
        </message>
    </context>
    <context>
        <name>PointProvenance</name>
        <message>
            <location filename="../../ui/models/point_provenance.py" line="33" />
            <source>Made: unknown (saved before TeachPad recorded how points are made)</source>
            <translation>来源：未知（保存于 TeachPad 记录点位来源之前）</translation>
        </message>
        <message>
            <location filename="../../ui/models/point_provenance.py" line="37" />
            <source>Made: {how}</source>
            <translation>来源：{how}</translation>
        </message>
        <message>
            <location filename="../../ui/models/point_provenance.py" line="39" />
            <source>File: {file}</source>
            <translation>文件：{file}</translation>
        </message>
        <message>
            <location filename="../../ui/models/point_provenance.py" line="42" />
            <source>When: {when}</source>
            <translation>时间：{when}</translation>
        </message>
        <message>
            <location filename="../../ui/models/point_provenance.py" line="45" />
            <source>Controller: {controller}</source>
            <translation>控制器：{controller}</translation>
        </message>
        <message>
            <location filename="../../ui/models/point_provenance.py" line="46" />
            <source>none</source>
            <translation>无</translation>
        </message>
        <message>
            <location filename="../../ui/models/point_provenance.py" line="51" />
            <source>Software: {software}</source>
            <translation>软件：{software}</translation>
        </message>
        <message>
            <location filename="../../ui/models/point_provenance.py" line="56" />
            <source>no controller</source>
            <translation>无控制器</translation>
        </message>
        <message>
            <location filename="../../ui/models/point_provenance.py" line="58" />
            <source>Last edited: {when} ({controller})</source>
            <translation>最后编辑：{when}（{controller}）</translation>
        </message>
    </context>
    <context>
        <name>PointSyncController</name>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="172" />
            <source>Teach</source>
            <translation>示教</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="183" />
            <source>Teaching P{id} at the current pose…</source>
            <translation>正在以当前位姿示教 P{id}…</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="193" />
            <source>No points to upload</source>
            <translation>没有要上传的点</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="195" />
            <source>Upload</source>
            <translation>上传</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="202" />
            <source>Uploading {n} points…</source>
            <translation>正在上传 {n} 个点…</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="228" />
            <source>Cancelling the upload…</source>
            <translation>正在取消上传…</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="236" />
            <source>There is no point P{id}</source>
            <translation>不存在点 P{id}</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="239" />
            <source>Speed {v} mm/s is out of range</source>
            <translation>速度 {v} mm/s 超出范围</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="241" />
            <source>Move</source>
            <translation>运动</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="250" />
            <source>Moving to {point} at {v} mm/s…</source>
            <translation>正在以 {v} mm/s 运动到 {point}…</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="305" />
            <source>The controller does not hold the plan's points (did it restart?): Restore all to re-create them.</source>
            <translation>控制器上没有该轨迹的点（控制器是否重启过？）：请点击“恢复全部”重新创建。</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="329" />
            <source>{what}: not connected to a controller</source>
            <translation>{what}：未连接控制器</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="332" />
            <source>{what}: wait until the current operation ends</source>
            <translation>{what}：请等待当前操作结束</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="363" />
            <source>link lost</source>
            <translation>通信中断</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="384" />
            <source>Connected to another controller ({endpoint}): {n} points are not known to be on it. Restore all to create them there.</source>
            <translation>已连接到另一台控制器（{endpoint}）：不知道它是否保存着这 {n} 个点。点击“恢复全部”在其上创建它们。</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="389" />
            <source>The controller restarted, or it is not the one the points were uploaded to: {n} points may be gone from it. Restore all to re-create them.</source>
            <translation>控制器已重启，或不是上传这些点的那台控制器：其上可能已没有这 {n} 个点。点击“恢复全部”重新创建它们。</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="417" />
            <source>Teach failed: {reason}</source>
            <translation>示教失败：{reason}</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="426" />
            <source>Move failed: {reason}</source>
            <translation>运动失败：{reason}</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="437" />
            <source>Teach P{id} failed: {reason}</source>
            <translation>示教 P{id} 失败：{reason}</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="442" />
            <source>P{id} was created on the controller, but its pose is not known yet</source>
            <translation>P{id} 已在控制器上创建，但其位姿尚未读取到</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="452" />
            <source>P{id} was added on the host while teaching; the controller now holds the taught pose: upload it to keep the host's values</source>
            <translation>示教期间上位机已添加了 P{id}；控制器上现为示教位姿：如需保留上位机的数值请上传</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="461" />
            <source>Teach P{id}: {reason}</source>
            <translation>示教 P{id}：{reason}</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="466" />
            <source>Taught P{id} at X {x:.3f}  Y {y:.3f}  Z {z:.3f}</source>
            <translation>已示教 P{id}：X {x:.3f}  Y {y:.3f}  Z {z:.3f}</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="486" />
            <source>Reached P{id}</source>
            <translation>已到达 P{id}</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="270" />
            <location filename="../../ui/controllers/point_sync.py" line="490" />
            <source>Move to P{id} stopped by the operator</source>
            <translation>运动到 P{id} 已由操作员停止</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="498" />
            <location filename="../../ui/controllers/point_sync.py" line="507" />
            <source>Move to P{id} failed: {reason}</source>
            <translation>运动到 P{id} 失败：{reason}</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="560" />
            <source>cancelled</source>
            <translation>已取消</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="563" />
            <source>stopped</source>
            <translation>已停止</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="575" />
            <source>Uploaded {n} points</source>
            <translation>已上传 {n} 个点</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="580" />
            <source>Upload stopped after {ok} of {total} points: {reason}</source>
            <translation>上传在 {ok}/{total} 个点后停止：{reason}</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/point_sync.py" line="587" />
            <source>Uploaded {ok} of {total} points; {failed} failed (P{id}: {reason})</source>
            <translation>已上传 {ok}/{total} 个点；{failed} 个失败（P{id}：{reason}）</translation>
        </message>
    </context>
    <context>
        <name>Points</name>
        <message>
            <location filename="../../app/points/point.py" line="181" />
            <location filename="../../app/points/provenance.py" line="53" />
            <source>unknown</source>
            <extracomment>The editable fields of a point, in table / CSV column order. Fields the controller stores: editing one of them makes the point "changed on host". Sent without an error, but the controller's status never changed (observe rule): most likely on the controller, not proven. Still needs an upload before a move relies on it.
----------
The longest text kept in one provenance field (a file name, a controller's endpoint).</extracomment>
            <translation>未知</translation>
        </message>
        <message>
            <location filename="../../app/points/point.py" line="182" />
            <source>on controller</source>
            <translation>已在控制器上</translation>
        </message>
        <message>
            <location filename="../../app/points/point.py" line="183" />
            <source>changed on host</source>
            <translation>上位机已修改</translation>
        </message>
        <message>
            <location filename="../../app/points/point.py" line="184" />
            <source>upload failed</source>
            <translation>上传失败</translation>
        </message>
        <message>
            <location filename="../../app/points/point.py" line="185" />
            <source>on controller, unconfirmed</source>
            <translation>已在控制器上（未确认）</translation>
        </message>
        <message>
            <location filename="../../app/points/provenance.py" line="54" />
            <source>taught from the pose</source>
            <translation>从当前位姿示教</translation>
        </message>
        <message>
            <location filename="../../app/points/provenance.py" line="55" />
            <source>typed</source>
            <translation>手动输入</translation>
        </message>
        <message>
            <location filename="../../app/points/provenance.py" line="56" />
            <source>imported</source>
            <translation>导入</translation>
        </message>
    </context>
    <context>
        <name>PointsModel</name>
        <message>
            <location filename="../../ui/messages_plan.py" line="162" />
            <location filename="../../ui/models/point_columns.py" line="63" />
            <source>none</source>
            <extracomment>Columns of the table: the point's fields in CSV order, with the sync state before the note. Custom roles. Text the tool cell accepts for "no tool frame" besides 200.</extracomment>
            <translation>无</translation>
        </message>
        <message>
            <location filename="../../ui/messages_plan.py" line="163" />
            <location filename="../../ui/models/point_columns.py" line="64" />
            <source>tool {n}</source>
            <translation>工具 {n}</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="131" />
            <source>ID</source>
            <extracomment>how the points made here are stamped (the window tells it the controller the link reaches)</extracomment>
            <translation>编号</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="132" />
            <source>Name</source>
            <translation>名称</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="133" />
            <source>Tool</source>
            <translation>工具</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="134" />
            <source>Sync</source>
            <translation>同步状态</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="135" />
            <source>Note</source>
            <translation>备注</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="142" />
            <source>Temp point id on the controller</source>
            <translation>控制器上的临时点编号</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="143" />
            <source>Tool frame (200 = none)</source>
            <translation>工具坐标系（200 = 无）</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="144" />
            <source>Whether the controller holds this point</source>
            <translation>控制器上是否有此点</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="145" />
            <source>mm, base frame</source>
            <translation>毫米，基坐标系</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="146" />
            <source>degrees</source>
            <translation>度</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="149" />
            <source>External axis (recorded only: the controller does not store it); CSV column {column}</source>
            <translation>外部轴（仅记录：控制器不保存）；CSV 列 {column}</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="217" />
            <source>no reason given</source>
            <translation>未给出原因</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="218" />
            <source>Upload failed: {reason}</source>
            <translation>上传失败：{reason}</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="221" />
            <source>Not known whether the controller holds this point (it restarted, it is another controller, or the arm did not arrive there): a move to it creates it again first</source>
            <translation>不知道控制器是否保存着此点（控制器已重启、是另一台控制器，或机械臂未到达该点）：移动到此点时会先重新创建它</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="225" />
            <source>The controller holds this point with these values</source>
            <translation>控制器上的此点与这些数值一致</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="226" />
            <source>Changed on the host (or new) since the last upload</source>
            <translation>自上次上传后已在上位机修改（或为新点）</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="228" />
            <source>Sent without an error, but the controller's status never changed: most likely there, not proven; upload it again before moving to it</source>
            <translation>发送无错误，但控制器状态一直未变：很可能已在控制器上，但未经证实；移动到该点前请重新上传</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="236" />
            <source>Tool frame {value}</source>
            <translation>工具坐标系 {value}</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="283" />
            <source>{point}, {column}: refused, {reason}</source>
            <translation>{point}，{column}：输入被拒绝，{reason}</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="313" />
            <source>Edit {point} {column}</source>
            <translation>编辑 {point} {column}</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="331" />
            <source>Add {point}</source>
            <translation>添加 {point}</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="362" />
            <source>Duplicate {point}</source>
            <translation>复制 {point}</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="364" />
            <source>Duplicate {n} points</source>
            <translation>复制 {n} 个点</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="383" />
            <source>Delete {point}</source>
            <translation>删除 {point}</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="385" />
            <source>Delete {n} points</source>
            <translation>删除 {n} 个点</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="401" />
            <source>Move up</source>
            <translation>上移</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="401" />
            <source>Move down</source>
            <translation>下移</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="424" />
            <source>Teach {point}</source>
            <translation>示教 {point}</translation>
        </message>
        <message>
            <location filename="../../ui/models/points_model.py" line="444" />
            <source>Import {n} points</source>
            <translation>导入 {n} 个点</translation>
        </message>
    </context>
    <context>
        <name>PointsPanel</name>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="184" />
            <source>Teach</source>
            <translation>示教</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="186" />
            <source>Create the next temp point on the controller from the robot's current pose (Ctrl+T)</source>
            <translation>以机器人当前位姿在控制器上创建下一个临时点（Ctrl+T）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="189" />
            <source>Add</source>
            <translation>添加</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="189" />
            <source>Add a point on the host (not on the controller yet)</source>
            <translation>在上位机添加一个点（尚未上传到控制器）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="190" />
            <source>Duplicate</source>
            <translation>复制</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="190" />
            <source>Copy the selected points under new ids</source>
            <translation>以新编号复制所选点</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="192" />
            <source>Delete</source>
            <translation>删除</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="193" />
            <source>Delete the selected points from the host's list</source>
            <translation>从上位机列表中删除所选点</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="195" />
            <source>Move the selected points up (Alt+Up)</source>
            <translation>上移所选点（Alt+↑）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="196" />
            <source>Move the selected points down (Alt+Down)</source>
            <translation>下移所选点（Alt+↓）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="198" />
            <source>Upload selected</source>
            <translation>上传所选</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="199" />
            <source>Create the selected points on the controller</source>
            <translation>在控制器上创建所选点</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="202" />
            <source>Upload changed</source>
            <translation>上传已修改</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="203" />
            <source>Upload every point not known to be on the controller</source>
            <translation>上传所有不确定在控制器上的点</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="205" />
            <source>Upload all</source>
            <translation>全部上传</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="205" />
            <source>Create every point on the controller</source>
            <translation>在控制器上创建所有点</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="207" />
            <location filename="../../ui/panels/points_parts.py" line="171" />
            <source>Restore all</source>
            <translation>恢复全部</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="208" />
            <source>Re-create all points after a controller restart</source>
            <translation>控制器重启后重新创建所有点</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="210" />
            <source>Cancel upload</source>
            <translation>取消上传</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="212" />
            <location filename="../../ui/panels/points_panel.py" line="405" />
            <source>Move to point</source>
            <translation>运动到点</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="213" />
            <source>Move the robot in a line to the selected point (asks first)</source>
            <translation>机器人以直线运动到所选点（会先确认）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="215" />
            <source>J7–J11</source>
            <translation>J7–J11</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="215" />
            <source>Show the external axes columns (J7–J11)</source>
            <translation>显示外部轴列（J7–J11）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="216" />
            <source>Find</source>
            <translation>查找</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="274" />
            <source>This cell cannot be edited: {why}</source>
            <translation>无法编辑此单元格：{why}</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="426" />
            <source>→ {cap} mm/s (reduced speed)</source>
            <translation>→ {cap} mm/s（降速模式）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_parts.py" line="134" />
            <source>Speed of Move to point</source>
            <translation>运动到点的速度</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_parts.py" line="135" />
            <source>Find:</source>
            <translation>查找：</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_parts.py" line="136" />
            <source>id or name</source>
            <translation>编号或名称</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_parts.py" line="165" />
            <source>The controller restarted, or it is another controller: it may not hold these points. Re-create them before running a plan.</source>
            <translation>控制器已重启，或是另一台控制器：它可能没有保存这些点。运行轨迹前请重新创建它们。</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_parts.py" line="192" />
            <source>Cancel</source>
            <translation>取消</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_parts.py" line="193" />
            <source>Uploading</source>
            <translation>正在上传</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="317" />
            <source>Added {point} at the robot's current pose</source>
            <translation>已在机器人当前位姿添加 {point}</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="321" />
            <source>pose copied from P{id}</source>
            <translation>位姿复制自 P{id}</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="323" />
            <source>pose set to zeros</source>
            <translation>位姿设为零</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="326" />
            <source>Added {point}, not from the controller: no live pose ({why})</source>
            <translation>已添加 {point}，位姿并非来自控制器：没有实时位姿（{why}）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="353" />
            <source>Deleted {n} points (Ctrl+Z to undo)</source>
            <translation>已删除 {n} 个点（Ctrl+Z 撤销）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="356" />
            <source>{point} is used by plan '{plan}' segment {k}</source>
            <translation>{point} 被轨迹“{plan}”的第 {k} 段使用</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="382" />
            <source>Select one point to move to</source>
            <translation>请选择一个要运动到的点</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_panel.py" line="391" />
            <source>Move the robot in a straight line to {point}?

X {x:.3f}  Y {y:.3f}  Z {z:.3f}
A {a:.3f}  B {b:.3f}  C {c:.3f}
Speed {v} mm/s</source>
            <translation>机器人以直线运动到 {point}？

X {x:.3f}  Y {y:.3f}  Z {z:.3f}
A {a:.3f}  B {b:.3f}  C {c:.3f}
速度 {v} mm/s</translation>
        </message>
        <message>
            <location filename="../../ui/panels/points_parts.py" line="199" />
            <source>%v of %m points</source>
            <translation>%v / %m 个点</translation>
        </message>
    </context>
    <context>
        <name>PoseStrip</name>
        <message>
            <location filename="../../ui/panels/pose_strip.py" line="69" />
            <source>live</source>
            <translation>实时</translation>
        </message>
        <message>
            <location filename="../../ui/panels/pose_strip.py" line="70" />
            <source>stale {age} s</source>
            <translation>过期 {age} 秒</translation>
        </message>
        <message>
            <location filename="../../ui/panels/pose_strip.py" line="71" />
            <source>stale</source>
            <translation>过期</translation>
        </message>
        <message>
            <location filename="../../ui/panels/pose_strip.py" line="72" />
            <location filename="../../ui/panels/pose_strip.py" line="306" />
            <location filename="../../ui/panels/pose_strip.py" line="307" />
            <source>unknown</source>
            <translation>未知</translation>
        </message>
        <message>
            <location filename="../../ui/panels/pose_strip.py" line="74" />
            <source>disconnected</source>
            <translation>未连接</translation>
        </message>
        <message>
            <location filename="../../ui/panels/pose_strip.py" line="75" />
            <source>connecting</source>
            <translation>正在连接</translation>
        </message>
        <message>
            <location filename="../../ui/panels/pose_strip.py" line="76" />
            <source>not answering</source>
            <translation>无应答</translation>
        </message>
        <message>
            <location filename="../../ui/panels/pose_strip.py" line="77" />
            <source>link down</source>
            <translation>链路中断</translation>
        </message>
        <message>
            <location filename="../../ui/panels/pose_strip.py" line="217" />
            <source>mm</source>
            <translation>mm</translation>
        </message>
        <message>
            <location filename="../../ui/panels/pose_strip.py" line="218" />
            <source>Mode</source>
            <translation>模式</translation>
        </message>
        <message>
            <location filename="../../ui/panels/pose_strip.py" line="219" />
            <source>Program</source>
            <translation>程序</translation>
        </message>
        <message>
            <location filename="../../ui/panels/pose_strip.py" line="220" />
            <source>The controller's work mode (register 560)</source>
            <translation>控制器工作模式（寄存器 560）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/pose_strip.py" line="221" />
            <source>The controller's program state (register 561)</source>
            <translation>控制器程序状态（寄存器 561）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/pose_strip.py" line="223" />
            <source>Whether the values shown were confirmed by the controller within the freshness limit</source>
            <translation>显示的数值是否在时效内得到控制器确认</translation>
        </message>
    </context>
    <context>
        <name>ProfileWords</name>
        <message>
            <location filename="../../ui/messages_profile.py" line="31" />
            <source>the robot profile cannot be used</source>
            <translation>机器人模型配置文件无法使用</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="32" />
            <source>{value} is not a finite number</source>
            <translation>{value} 不是有限的数</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="33" />
            <source>expected a list of six numbers X Y Z A B C, got {value}</source>
            <translation>应为六个数（X Y Z A B C）的列表，实际为 {value}</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="36" />
            <source>expected an object with {keys}</source>
            <translation>应为含有 {keys} 的对象</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="37" />
            <source>missing {keys}</source>
            <translation>缺少 {keys}</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="38" />
            <source>the name {value} is not text</source>
            <translation>名称 {value} 不是文本</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="39" />
            <source>min_deg {low} is not below max_deg {high}</source>
            <translation>min_deg {low} 不小于 max_deg {high}</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="40" />
            <source>a robot profile is a JSON object</source>
            <translation>机器人模型配置文件应为 JSON 对象</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="41" />
            <source>not a robot profile: its format is {value}, expected {expected}</source>
            <translation>不是机器人模型配置文件：format 为 {value}，应为 {expected}</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="44" />
            <source>profile version {value} is not supported (this TeachPad reads version {expected})</source>
            <translation>不支持配置文件版本 {value}（本 TeachPad 读取版本 {expected}）</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="47" />
            <source>joints: expected a list of 1 to {most} joints</source>
            <translation>joints：应为含 1 到 {most} 个关节的列表</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="48" />
            <source>home_deg: expected {count} numbers, one per joint</source>
            <translation>home_deg：应为 {count} 个数，每个关节一个</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="49" />
            <source>too large for a robot profile (over {kb} kB)</source>
            <translation>文件过大，不是机器人模型配置文件（超过 {kb} kB）</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="50" />
            <source>cannot read the robot profile ({cause})</source>
            <translation>无法读取机器人模型配置文件（{cause}）</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="51" />
            <source>the robot profile is not UTF-8 text</source>
            <translation>机器人模型配置文件不是 UTF-8 文本</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="52" />
            <source>not valid JSON (line {line}, column {column})</source>
            <translation>不是有效的 JSON（第 {line} 行，第 {column} 列）</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="54" />
            <source>cannot read the {what} ({cause})</source>
            <translation>无法读取{what}（{cause}）</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="55" />
            <source>the {what} is not UTF-8 text</source>
            <translation>{what}不是 UTF-8 文本</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="56" />
            <source>the {what} is not valid JSON (line {line}, column {column})</source>
            <translation>{what}不是有效的 JSON（第 {line} 行，第 {column} 列）</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="61" />
            <source>register profile</source>
            <translation>寄存器配置</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="62" />
            <source>safety profile</source>
            <translation>安全配置</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="70" />
            <source>the file is too large ({size} bytes, at most {limit})</source>
            <translation>文件太大（{size} 字节，最多 {limit}）</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="73" />
            <source>the file does not exist</source>
            <translation>文件不存在</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="74" />
            <location filename="../../ui/messages_profile.py" line="75" />
            <source>permission denied</source>
            <translation>没有访问权限</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="76" />
            <source>it is a folder, not a file</source>
            <translation>这是文件夹，不是文件</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="77" />
            <source>a folder on its path is a file</source>
            <translation>其路径中的某个文件夹实际上是文件</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="78" />
            <source>the file name is too long</source>
            <translation>文件名太长</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="79" />
            <source>the disk could not be read</source>
            <translation>无法读取磁盘</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="81" />
            <source>system error {errno}</source>
            <translation>系统错误 {errno}</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="82" />
            <source>joint {n}</source>
            <translation>关节 {n}</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="83" />
            <source>joint {n} {key}</source>
            <translation>关节 {n} 的 {key}</translation>
        </message>
        <message>
            <location filename="../../ui/messages_profile.py" line="151" />
            <source>{why}; the remembered connection settings are used until an administrator saves a register profile</source>
            <translation>{why}；在管理员保存寄存器配置之前，使用记住的连接设置</translation>
        </message>
    </context>
    <context>
        <name>ProgramPanel</name>
        <message>
            <location filename="../../ui/panels/program_panel.py" line="136" />
            <source>Program</source>
            <translation>程序</translation>
        </message>
        <message>
            <location filename="../../ui/panels/program_panel.py" line="137" />
            <source>Program no.:</source>
            <translation>程序号：</translation>
        </message>
        <message>
            <location filename="../../ui/panels/program_panel.py" line="137" />
            <source>Run mode:</source>
            <translation>运行方式：</translation>
        </message>
        <message>
            <location filename="../../ui/panels/program_panel.py" line="137" />
            <source>Cycles:</source>
            <translation>循环次数：</translation>
        </message>
        <message>
            <location filename="../../ui/panels/program_panel.py" line="137" />
            <source>Speed:</source>
            <translation>速度：</translation>
        </message>
        <message>
            <location filename="../../ui/panels/program_panel.py" line="142" />
            <source>endless</source>
            <translation>无限循环</translation>
        </message>
        <message>
            <location filename="../../ui/panels/program_panel.py" line="143" />
            <source>Number of cycles in cycle mode; 0 runs until stopped</source>
            <translation>循环模式下的循环次数；0 表示一直运行直到停止</translation>
        </message>
        <message>
            <location filename="../../ui/panels/program_panel.py" line="144" />
            <source>Run program</source>
            <translation>运行程序</translation>
        </message>
        <message>
            <location filename="../../ui/panels/program_panel.py" line="145" />
            <location filename="../../ui/panels/program_panel.py" line="147" />
            <source>Go to zero</source>
            <translation>回零</translation>
        </message>
        <message>
            <location filename="../../ui/panels/program_panel.py" line="146" />
            <source>All axes</source>
            <translation>所有轴</translation>
        </message>
        <message>
            <location filename="../../ui/panels/program_panel.py" line="201" />
            <source>{speed} %</source>
            <translation>{speed} %</translation>
        </message>
        <message>
            <location filename="../../ui/panels/program_panel.py" line="202" />
            <source>{speed} % (capped by reduced speed; {asked} % set)</source>
            <translation>{speed} %（受降速模式限制；设定为 {asked} %）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/program_panel.py" line="212" />
            <source>The controller is in Manual mode. Switch it to Auto and run program {id} ({mode}) at {speed}? The arm will move.</source>
            <translation>控制器处于手动模式。切换到自动模式，并以 {speed} 运行程序 {id}（{mode}）？机械臂将会运动。</translation>
        </message>
        <message>
            <location filename="../../ui/panels/program_panel.py" line="216" />
            <source>Run program {id} ({mode}) at {speed}? The arm will move.</source>
            <translation>以 {speed} 速度运行程序 {id}（{mode}）？机械臂将会运动。</translation>
        </message>
        <message>
            <location filename="../../ui/panels/program_panel.py" line="244" />
            <source>→ {cap} % (reduced speed)</source>
            <translation>→ {cap} %（降速模式）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/program_panel.py" line="246" />
            <source>Reduced-speed mode: the program runs at {cap} % at most</source>
            <translation>降速模式：程序最多以 {cap} % 运行</translation>
        </message>
        <message>
            <location filename="../../ui/panels/program_panel.py" line="256" />
            <source>Not in reduced-speed mode: go to zero runs at the controller's own speed, which TeachPad cannot cap</source>
            <translation>降速模式下不可用：回零以控制器自身的速度运行，TeachPad 无法限制该速度</translation>
        </message>
        <message>
            <location filename="../../ui/panels/program_panel.py" line="218" />
            <source>Confirm program run</source>
            <translation>确认运行程序</translation>
        </message>
        <message>
            <location filename="../../ui/panels/program_panel.py" line="226" />
            <source>all axes</source>
            <translation>所有轴</translation>
        </message>
        <message>
            <location filename="../../ui/panels/program_panel.py" line="230" />
            <source>The controller is in Manual mode. Switch it to Auto and move {which} to zero? The arm will move.</source>
            <translation>控制器处于手动模式。切换到自动模式，并将 {which} 回零？机械臂将会运动。</translation>
        </message>
        <message>
            <location filename="../../ui/panels/program_panel.py" line="234" />
            <source>Move {which} to zero? The arm will move.</source>
            <translation>将 {which} 回零？机械臂将会运动。</translation>
        </message>
        <message>
            <location filename="../../ui/panels/program_panel.py" line="235" />
            <source>Confirm go to zero</source>
            <translation>确认回零</translation>
        </message>
    </context>
    <context>
        <name>ProjectController</name>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="143" />
            <source>Undo</source>
            <extracomment>The longest a close, a save or a discard waits for the autosave being written (s): a 58 MB project is written in about a second; a stuck disk must not hold the window for ever.</extracomment>
            <translation>撤销</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="145" />
            <source>Redo</source>
            <translation>重做</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="149" />
            <source>&amp;New project</source>
            <translation>新建工程(&amp;N)</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="150" />
            <source>&amp;Open project…</source>
            <translation>打开工程(&amp;O)…</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="151" />
            <source>&amp;Save project</source>
            <translation>保存工程(&amp;S)</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="152" />
            <source>Save project &amp;as…</source>
            <translation>工程另存为(&amp;A)…</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="153" />
            <source>&amp;Import points (CSV)…</source>
            <translation>导入点 (CSV)(&amp;I)…</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="154" />
            <source>&amp;Export points (CSV)…</source>
            <translation>导出点 (CSV)(&amp;E)…</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="184" />
            <source>untitled</source>
            <translation>未命名</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="219" />
            <source>Open project</source>
            <translation>打开工程</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="227" />
            <location filename="../../ui/controllers/project_controller.py" line="265" />
            <location filename="../../ui/controllers/project_controller.py" line="419" />
            <source>Project in use</source>
            <translation>工程正在使用中</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="232" />
            <location filename="../../ui/controllers/project_controller.py" line="235" />
            <source>Cannot open project</source>
            <translation>无法打开工程</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="238" />
            <source>Opened {path}</source>
            <translation>已打开 {path}</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="250" />
            <source>Save project</source>
            <translation>保存工程</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="271" />
            <location filename="../../ui/controllers/project_controller.py" line="274" />
            <source>Cannot save project</source>
            <translation>无法保存工程</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="286" />
            <source>Saved {path}</source>
            <translation>已保存 {path}</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="292" />
            <source>Import points</source>
            <translation>导入点</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="299" />
            <location filename="../../ui/controllers/project_controller.py" line="302" />
            <location filename="../../ui/controllers/project_controller.py" line="317" />
            <source>Cannot import points</source>
            <translation>无法导入点</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="319" />
            <source>{added} added, {updated} updated, {unchanged} unchanged, {removed} removed</source>
            <translation>新增 {added} 个，更新 {updated} 个，未变 {unchanged} 个，删除 {removed} 个</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="322" />
            <source>Imported {path}: {report}</source>
            <translation>已导入 {path}：{report}</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="335" />
            <source>Export points</source>
            <translation>导出点</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="342" />
            <source>Cannot export points</source>
            <translation>无法导出点</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="345" />
            <source>Exported {n} points to {path}</source>
            <translation>已导出 {n} 个点到 {path}</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="393" />
            <source>Autosave failed: {reason}</source>
            <translation>自动保存失败：{reason}</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="401" />
            <location filename="../../ui/controllers/project_controller.py" line="454" />
            <source>The autosave {path} is still being written after {seconds} s.</source>
            <translation>自动保存 {path} 在 {seconds} 秒后仍在写入。</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="435" />
            <location filename="../../ui/controllers/project_controller.py" line="438" />
            <source>Cannot recover autosave</source>
            <translation>无法恢复自动保存</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="441" />
            <source>Recovered the autosave {path}</source>
            <translation>已恢复自动保存 {path}</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="488" />
            <source>Cannot lock {path}: {reason}</source>
            <translation>无法锁定 {path}：{reason}</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="498" />
            <source>{path} is open in another TeachPad (process {pid} on {host}, since {started}). Close it there first; its autosave belongs to that TeachPad and is not offered for recovery here.</source>
            <translation>{path} 已在另一个 TeachPad 中打开（主机 {host} 上的进程 {pid}，自 {started} 起）。请先在那里关闭它；它的自动保存属于那个 TeachPad，此处不提供恢复。</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="540" />
            <source>TeachPad projects (*.teachpad.json *.json);;All files (*)</source>
            <translation>TeachPad 工程 (*.teachpad.json *.json);;所有文件 (*)</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_controller.py" line="543" />
            <source>CSV files (*.csv);;All files (*)</source>
            <translation>CSV 文件 (*.csv);;所有文件 (*)</translation>
        </message>
    </context>
    <context>
        <name>ProjectDialogs</name>
        <message>
            <location filename="../../ui/controllers/project_dialogs.py" line="54" />
            <source>Unsaved changes</source>
            <translation>未保存的更改</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_dialogs.py" line="55" />
            <source>Save the changes to {name}?</source>
            <translation>保存对 {name} 的更改？</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_dialogs.py" line="71" />
            <source>an unsaved project</source>
            <translation>未保存的工程</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_dialogs.py" line="73" />
            <source>TeachPad was not closed properly. An autosave of {what} is newer than the saved file:
{autosave}

Recover it?</source>
            <translation>TeachPad 上次未正常关闭。{what} 的自动保存比已保存的文件更新：
{autosave}

是否恢复？</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_dialogs.py" line="78" />
            <source>Recover autosave</source>
            <translation>恢复自动保存</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_dialogs.py" line="90" />
            <source>The file has no points. Importing it in replace mode removes all {n} points of the project.

Remove them all?</source>
            <translation>该文件中没有点。以替换方式导入将删除工程中全部 {n} 个点。

确定全部删除吗？</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_dialogs.py" line="105" />
            <source>Replace all points</source>
            <translation>替换全部点</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_dialogs.py" line="106" />
            <source>Merge (update the same ids, append new ones)</source>
            <translation>合并（更新相同编号，追加新点）</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_dialogs.py" line="95" />
            <location filename="../../ui/controllers/project_dialogs.py" line="109" />
            <source>Import points</source>
            <translation>导入点</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/project_dialogs.py" line="110" />
            <source>Import mode:</source>
            <translation>导入方式：</translation>
        </message>
    </context>
    <context>
        <name>Protocol</name>
        <message>
            <location filename="../../app/protocol/enums.py" line="40" />
            <source>run program</source>
            <translation>运行程序</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="41" />
            <source>incremental move (joint)</source>
            <translation>增量运动（关节）</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="42" />
            <source>incremental move (base)</source>
            <translation>增量运动（基坐标）</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="43" />
            <source>move to temp point</source>
            <translation>运动到临时点</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="44" />
            <source>teach enable</source>
            <translation>示教使能</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="45" />
            <source>teach disable</source>
            <translation>示教关闭</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="46" />
            <source>create temp point</source>
            <translation>创建临时点</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="66" />
            <source>manual</source>
            <translation>手动</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="67" />
            <source>auto</source>
            <translation>自动</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="68" />
            <source>Modbus teach</source>
            <translation>Modbus 示教</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="81" />
            <source>stopped</source>
            <translation>已停止</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="82" />
            <source>running</source>
            <translation>运行中</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="83" />
            <source>paused</source>
            <translation>已暂停</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="96" />
            <source>single step</source>
            <translation>单步</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="97" />
            <source>single run</source>
            <translation>单次运行</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="98" />
            <source>cycle</source>
            <translation>循环</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="112" />
            <source>base</source>
            <translation>基坐标系</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="113" />
            <source>user</source>
            <translation>用户坐标系</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="114" />
            <source>tool</source>
            <translation>工具坐标系</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="115" />
            <source>joint</source>
            <translation>关节坐标系</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="134" />
            <location filename="../../app/protocol/enums.py" line="225" />
            <location filename="../../app/protocol/enums.py" line="247" />
            <source>emergency stop</source>
            <translation>急停</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="135" />
            <location filename="../../app/protocol/enums.py" line="226" />
            <location filename="../../app/protocol/enums.py" line="248" />
            <source>servo alarm</source>
            <translation>伺服报警</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="136" />
            <location filename="../../app/protocol/enums.py" line="227" />
            <location filename="../../app/protocol/enums.py" line="249" />
            <source>brake alarm</source>
            <translation>抱闸报警</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="137" />
            <location filename="../../app/protocol/enums.py" line="251" />
            <source>algorithm alarm</source>
            <translation>算法报警</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="138" />
            <source>encoder angle alarm</source>
            <translation>编码器角度报警</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="222" />
            <location filename="../../app/protocol/enums.py" line="239" />
            <location filename="../../app/protocol/enums.py" line="244" />
            <source>initial</source>
            <translation>初始</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="223" />
            <source>done</source>
            <translation>完成</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="224" />
            <location filename="../../app/protocol/enums.py" line="246" />
            <source>work mode error</source>
            <translation>工作模式错误</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="228" />
            <location filename="../../app/protocol/enums.py" line="250" />
            <source>bus servo initialisation error</source>
            <translation>总线伺服初始化错误</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="229" />
            <source>moving</source>
            <translation>运动中</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="230" />
            <source>data length error</source>
            <translation>数据长度错误</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="231" />
            <source>encoder angle read error</source>
            <translation>编码器角度读取错误</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="232" />
            <source>encoder angle update error</source>
            <translation>编码器角度更新错误</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="233" />
            <source>calculation error</source>
            <translation>计算错误</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="234" />
            <source>algorithm error while moving</source>
            <translation>运动中算法错误</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="235" />
            <source>motion timeout</source>
            <translation>运动超时</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="236" />
            <source>bad end point id</source>
            <translation>终点编号错误</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="240" />
            <location filename="../../app/protocol/enums.py" line="245" />
            <source>success</source>
            <translation>成功</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="241" />
            <source>bad point id</source>
            <translation>点编号错误</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="252" />
            <source>teach speed ratio not zero: enable/disable refused</source>
            <translation>示教速度比例不为零：拒绝使能/关闭</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="265" />
            <source>unknown status {code}</source>
            <translation>未知状态 {code}</translation>
        </message>
        <message>
            <location filename="../../app/protocol/enums.py" line="266" />
            <source>sent, waiting for the controller</source>
            <translation>已发送，等待控制器结果</translation>
        </message>
    </context>
    <context>
        <name>QFileDialog</name>
        <message>
            <location filename="../../ui/qt_words.py" line="16" />
            <source>&amp;Look in:</source>
            <translation>查找范围(&amp;L)：</translation>
        </message>
        <message>
            <location filename="../../ui/qt_words.py" line="17" />
            <source>Files of &amp;type:</source>
            <translation>文件类型(&amp;T)：</translation>
        </message>
    </context>
    <context>
        <name>RegisterMapMenu</name>
        <message>
            <location filename="../../ui/controllers/selftest_watch.py" line="59" />
            <source>Check the controller's &amp;register map…</source>
            <translation>检查控制器的寄存器映射(&amp;R)…</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/selftest_watch.py" line="62" />
            <source>Read the documented registers (nothing is written) and check them against the register profile</source>
            <translation>读取文档中定义的寄存器（不写入任何内容），并与寄存器配置核对</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/selftest_watch.py" line="92" />
            <source>register map</source>
            <translation>寄存器映射</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/selftest_watch.py" line="95" />
            <source>The controller's register map does not match the register profile: Help → Check the controller's register map…</source>
            <translation>控制器的寄存器映射与寄存器配置不一致：帮助 → 检查控制器的寄存器映射…</translation>
        </message>
    </context>
    <context>
        <name>RegisterProfileDialog</name>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="152" />
            <source>Register profile</source>
            <extracomment>apply(profile, reconnect) -&gt; None when saved, else the reason (already in the user's language)</extracomment>
            <translation>寄存器配置</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="154" />
            <source>Name:</source>
            <translation>名称：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="155" />
            <source>Float word order:</source>
            <translation>浮点字序：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="156" />
            <source>Unit id:</source>
            <translation>从站地址：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="157" />
            <source>Command completion:</source>
            <translation>指令完成判定：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="158" />
            <source>Unconfirmed after:</source>
            <translation>未确认判定时间：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="159" />
            <source>Poll timeout:</source>
            <translation>轮询超时：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="160" />
            <source>Date/time layout:</source>
            <translation>日期/时间格式：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="161" />
            <source>Lowest point id:</source>
            <translation>最小点号：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="162" />
            <source>Highest point id:</source>
            <translation>最大点号：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="166" />
            <source>Low word first (CDAB, default)</source>
            <translation>低字在前（CDAB，默认）</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="167" />
            <source>High word first (ABCD)</source>
            <translation>高字在前（ABCD）</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="170" />
            <source>automatic (probe GV291 once)</source>
            <translation>自动（试探一次 GV291）</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="171" />
            <source>sentinel (GV291 keeps what the host writes)</source>
            <translation>哨兵值（GV291 保留上位机写入的值）</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="172" />
            <source>observe (GV291 read-only or ignores writes)</source>
            <translation>观察（GV291 只读或忽略写入）</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="176" />
            <source>split words (576 = year, 577 = month·256 + day)</source>
            <translation>分两个寄存器（576 = 年，577 = 月·256 + 日）</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="177" />
            <source>packed 32-bit (year in the high word)</source>
            <translation>32 位打包（年在高字）</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="178" />
            <source>automatic</source>
            <translation>自动</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="179" />
            <source>automatic (by transport)</source>
            <translation>自动（按通信方式）</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="180" />
            <source>Reconnect now to apply it</source>
            <translation>立即重新连接以应用</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="181" />
            <source>Otherwise it applies at the next connection</source>
            <translation>否则在下次连接时生效</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="182" />
            <source>Load…</source>
            <translation>载入…</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="183" />
            <source>Save as…</source>
            <translation>另存为…</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="184" />
            <source>Defaults</source>
            <translation>默认值</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="186" />
            <source>Save and apply</source>
            <translation>保存并应用</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="216" />
            <source>In force: “{name}”, revision {rev}, saved {saved}</source>
            <translation>当前生效：“{name}”，第 {rev} 版，保存于 {saved}</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="220" />
            <source>In force: the remembered connection settings (no register profile saved yet)</source>
            <translation>当前生效：记住的连接设置（尚未保存寄存器配置）</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="268" />
            <source>Not loaded: {why}</source>
            <translation>未载入：{why}</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="271" />
            <source>Loaded “{name}” from {file}; press Save and apply to use it</source>
            <translation>已从 {file} 载入“{name}”；按“保存并应用”后生效</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="287" />
            <source>Cannot write {file}: {why}</source>
            <translation>无法写入 {file}：{why}</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="290" />
            <source>Saved to {file}</source>
            <translation>已保存到 {file}</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="307" />
            <source>Load a register profile</source>
            <translation>载入寄存器配置</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="307" />
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="313" />
            <source>Register profiles (*.json)</source>
            <translation>寄存器配置 (*.json)</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/register_profile_dialog.py" line="313" />
            <source>Save the register profile as</source>
            <translation>寄存器配置另存为</translation>
        </message>
    </context>
    <context>
        <name>RobotModelSource</name>
        <message>
            <location filename="../../ui/panels/view3d_robot.py" line="185" />
            <source>The robot model remembered from the last session could not be loaded: %1. The default robot model (%2) is used.</source>
            <translation>上次使用的机器人模型无法加载：%1。现使用默认机器人模型（%2）。</translation>
        </message>
    </context>
    <context>
        <name>RoleDialog</name>
        <message>
            <location filename="../../ui/dialogs/role_dialog.py" line="30" />
            <source>Log in</source>
            <translation>登录</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/role_dialog.py" line="39" />
            <source>Now: {role}</source>
            <translation>当前：{role}</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/role_dialog.py" line="43" />
            <source>Set this role's password</source>
            <translation>设置此角色的密码</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/role_dialog.py" line="45" />
            <source>Log out (operator)</source>
            <translation>注销（回到操作员）</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/role_dialog.py" line="48" />
            <source>Role:</source>
            <translation>角色：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/role_dialog.py" line="49" />
            <source>Password:</source>
            <translation>密码：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/role_dialog.py" line="50" />
            <source>Repeat:</source>
            <translation>再次输入：</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/role_dialog.py" line="77" />
            <source>No administrator password is set yet: choose the administrator role, type a password twice and press “Set this role's password”.</source>
            <translation>尚未设置管理员密码：请选择管理员角色，输入两次密码，然后按“设置此角色的密码”。</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/role_dialog.py" line="81" />
            <location filename="../../ui/dialogs/role_dialog.py" line="110" />
            <source>No password is set for this role; an administrator sets it.</source>
            <translation>此角色尚未设置密码；请由管理员设置。</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/role_dialog.py" line="108" />
            <source>Wrong password for the {role} role</source>
            <translation>{role}角色的密码错误</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/role_dialog.py" line="128" />
            <source>The two passwords differ: nothing was set. Type the same password twice.</source>
            <translation>两次输入的密码不一致：未作任何设置。请两次输入相同的密码。</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/role_dialog.py" line="139" />
            <source>The password could not be saved: {why}</source>
            <translation>无法保存密码：{why}</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/role_dialog.py" line="143" />
            <source>Password set for the {role} role</source>
            <translation>已设置{role}角色的密码</translation>
        </message>
    </context>
    <context>
        <name>Runner</name>
        <message>
            <location filename="../../app/plan/runner.py" line="92" />
            <source>ready</source>
            <translation>就绪</translation>
        </message>
        <message>
            <location filename="../../app/plan/runner.py" line="93" />
            <source>running</source>
            <translation>运行中</translation>
        </message>
        <message>
            <location filename="../../app/plan/runner.py" line="94" />
            <source>finished</source>
            <translation>已完成</translation>
        </message>
        <message>
            <location filename="../../app/plan/runner.py" line="95" />
            <source>stopped</source>
            <translation>已停止</translation>
        </message>
        <message>
            <location filename="../../app/plan/runner.py" line="96" />
            <source>failed</source>
            <translation>失败</translation>
        </message>
    </context>
    <context>
        <name>SafetyController</name>
        <message>
            <location filename="../../ui/controllers/safety.py" line="210" />
            <source>operator</source>
            <translation>操作员</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety.py" line="211" />
            <source>engineer</source>
            <translation>工程师</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety.py" line="212" />
            <source>administrator</source>
            <translation>管理员</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety.py" line="219" />
            <source>Needs the {need} role (you are {role}); log in from the Safety menu</source>
            <translation>需要{need}角色（当前为{role}）；请从“安全”菜单登录</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety.py" line="464" />
            <source>{axis} = {value:.1f} is within stopping distance of the keep-out zone '{box}' (at {limit:.1f})</source>
            <translation>{axis} = {value:.1f}，已进入禁区“{box}”的停止距离内（边界 {limit:.1f}）</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety.py" line="468" />
            <source>{axis} = {value:.1f} is within stopping distance of the limit at {limit:.1f}</source>
            <translation>{axis} = {value:.1f}，已进入限位 {limit:.1f} 的停止距离内</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety.py" line="470" />
            <source>{axis} = {value:.1f} mm is outside the allowed work space (limit {limit:.1f} mm)</source>
            <translation>{axis} = {value:.1f} mm 超出允许的工作空间（限值 {limit:.1f} mm）</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety.py" line="473" />
            <source>The path enters the keep-out zone '{box}' ({axis} = {value:.1f} mm, its face at {limit:.1f} mm)</source>
            <translation>路径进入禁区“{box}”（{axis} = {value:.1f} mm，边界在 {limit:.1f} mm）</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety.py" line="477" />
            <source>{axis} = {value:.1f}° is beyond its limit {limit:.1f}°</source>
            <translation>{axis} = {value:.1f}° 超出限位 {limit:.1f}°</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety.py" line="480" />
            <source>Speed {value:g} mm/s is above the {limit:g} mm/s allowed in reduced-speed mode</source>
            <translation>速度 {value:g} mm/s 超过降速模式允许的 {limit:g} mm/s</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety.py" line="482" />
            <source>Speed {value:g} mm/s is above the {limit:g} mm/s allowed</source>
            <translation>速度 {value:g} mm/s 超过允许的 {limit:g} mm/s</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety.py" line="486" />
            <source>Jog speed {value:g} % is above the {limit:g} % allowed in reduced-speed mode</source>
            <translation>点动速度 {value:g} % 超过降速模式允许的 {limit:g} %</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety.py" line="488" />
            <source>Jog speed {value:g} % is above the {limit:g} % allowed</source>
            <translation>点动速度 {value:g} % 超过允许的 {limit:g} %</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety.py" line="493" />
            <source>Segment {k}: {text}</source>
            <translation>第 {k} 段：{text}</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety.py" line="503" />
            <source>Jog stopped before the limit: {why}</source>
            <translation>点动已在到达边界前停止：{why}</translation>
        </message>
    </context>
    <context>
        <name>SafetyMenu</name>
        <message>
            <location filename="../../ui/controllers/safety_menu.py" line="145" />
            <source>&amp;Safety</source>
            <extracomment>measured stopping's summary lines for the bundle (app/safety/stopping.py; None: none kept)</extracomment>
            <translation>安全(&amp;S)</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety_menu.py" line="146" />
            <source>Log &amp;in…</source>
            <translation>登录(&amp;I)…</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety_menu.py" line="147" />
            <source>Log &amp;out (operator)</source>
            <translation>注销(&amp;O)（回到操作员）</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety_menu.py" line="148" />
            <source>&amp;Reduced speed</source>
            <translation>降速模式(&amp;R)</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety_menu.py" line="149" />
            <source>Safety &amp;envelope…</source>
            <translation>安全范围(&amp;E)…</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety_menu.py" line="150" />
            <source>Re&amp;gister profile…</source>
            <translation>寄存器配置(&amp;G)…</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety_menu.py" line="152" />
            <source>Word order, unit id, completion rule, poll timeout (administrator)</source>
            <translation>字序、从站地址、完成判定、轮询超时（管理员）</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety_menu.py" line="154" />
            <source>&amp;Passwords and lock…</source>
            <translation>密码与锁定(&amp;P)…</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety_menu.py" line="156" />
            <source>Set, change or clear passwords; the idle lock time (administrator)</source>
            <translation>设置、修改或清除密码；空闲锁定时间（管理员）</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety_menu.py" line="158" />
            <source>&amp;Audit trail…</source>
            <translation>审计记录(&amp;A)…</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety_menu.py" line="159" />
            <source>Write a &amp;support bundle…</source>
            <translation>生成支持包(&amp;S)…</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety_menu.py" line="173" />
            <source>Role: {role} · reduced speed</source>
            <translation>角色：{role} · 降速模式</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety_menu.py" line="173" />
            <source>Role: {role}</source>
            <translation>角色：{role}</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety_menu.py" line="183" />
            <source>Cap jog and move speeds (anyone may switch it on)</source>
            <translation>限制点动与移动速度（任何人都可开启）</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety_menu.py" line="196" />
            <source>safety</source>
            <translation>安全</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety_menu.py" line="259" />
            <source>The register profile could not be saved: {why}</source>
            <translation>寄存器配置无法保存：{why}</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety_menu.py" line="264" />
            <source>Register profile “{name}” saved (revision {rev})</source>
            <translation>寄存器配置“{name}”已保存（第 {rev} 版）</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety_menu.py" line="278" />
            <source>Zip files (*.zip)</source>
            <translation>Zip 文件 (*.zip)</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety_menu.py" line="285" />
            <source>Write a support bundle</source>
            <translation>生成支持包</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety_menu.py" line="317" />
            <source>The support bundle could not be written: {why}</source>
            <translation>无法生成支持包：{why}</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety_menu.py" line="320" />
            <source>Support bundle</source>
            <translation>支持包</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/safety_menu.py" line="326" />
            <source>Support bundle written: {file} ({n} files)</source>
            <translation>支持包已生成：{file}（{n} 个文件）</translation>
        </message>
    </context>
    <context>
        <name>SegmentEditorBox</name>
        <message>
            <location filename="../../ui/panels/planner_widgets.py" line="422" />
            <source>Segments</source>
            <translation>轨迹段</translation>
        </message>
        <message>
            <location filename="../../ui/panels/planner_widgets.py" line="422" />
            <source>Segments of “{plan}”</source>
            <translation>轨迹“{plan}”的轨迹段</translation>
        </message>
    </context>
    <context>
        <name>SegmentTableModel</name>
        <message>
            <location filename="../../ui/models/segment_model.py" line="121" />
            <source>Type</source>
            <translation>类型</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="122" />
            <source>Middle point</source>
            <translation>中间点</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="123" />
            <source>End point</source>
            <translation>终点</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="125" />
            <source>Orientation</source>
            <translation>姿态</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="127" />
            <source>Tool</source>
            <translation>工具</translation>
        </message>
        <message>
            <location filename="../../ui/models/plan_columns.py" line="74" />
            <source>changes</source>
            <translation>姿态变化</translation>
        </message>
        <message>
            <location filename="../../ui/models/plan_columns.py" line="75" />
            <source>kept</source>
            <translation>姿态保持</translation>
        </message>
        <message>
            <location filename="../../ui/models/plan_columns.py" line="101" />
            <source>error</source>
            <translation>错误</translation>
        </message>
        <message>
            <location filename="../../ui/models/plan_columns.py" line="102" />
            <source>needs upload</source>
            <translation>需要上传</translation>
        </message>
        <message>
            <location filename="../../ui/models/plan_columns.py" line="103" />
            <source>warning</source>
            <translation>警告</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="120" />
            <source>Check</source>
            <translation>检查</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="124" />
            <source>Speed</source>
            <translation>速度</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="126" />
            <source>Ignore mid.</source>
            <translation>忽略中间点</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="128" />
            <source>Length</source>
            <translation>长度</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="129" />
            <source>Time</source>
            <translation>时间</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="220" />
            <source>Checks before running: hover the icon for details</source>
            <translation>运行前检查：鼠标悬停在图标上查看详情</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="221" />
            <source>Speed in mm/s (GV225)</source>
            <translation>速度，单位 mm/s（GV225）</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="222" />
            <source>Middle point of an arc (GV200)</source>
            <translation>圆弧的中间点（GV200）</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="223" />
            <source>End point (GV201)</source>
            <translation>终点（GV201）</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="224" />
            <source>Orientation kept constant or changing along the move (GV202)</source>
            <translation>运动中姿态保持不变或变化（GV202）</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="225" />
            <source>Ignore the arc's middle point orientation (GV203)</source>
            <translation>忽略圆弧中间点的姿态（GV203）</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="226" />
            <source>Tool frame of the move (GV245)</source>
            <translation>运动使用的工具坐标系（GV245）</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="227" />
            <source>Estimated path length</source>
            <translation>估计路径长度</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="228" />
            <source>Estimated time: length / speed plus a fixed overhead per segment</source>
            <translation>估计时间：长度 / 速度，加上每段固定开销</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="331" />
            <source>Segment {n}: no problems found</source>
            <translation>第 {n} 段：未发现问题</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="336" />
            <source>Point P{id} does not exist</source>
            <translation>点 P{id} 不存在</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="371" />
            <source>Segment {n}, {column}: refused, {reason}</source>
            <translation>第 {n} 段，{column}：输入被拒绝，{reason}</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="385" />
            <source>Edit segment {n} {column}</source>
            <translation>编辑第 {n} 段 {column}</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="397" />
            <source>Add {kind} segment</source>
            <translation>添加{kind}段</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="414" />
            <source>Add {n} segments</source>
            <translation>添加 {n} 段</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="423" />
            <source>Delete segment {n}</source>
            <translation>删除第 {n} 段</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="425" />
            <source>Delete {n} segments</source>
            <translation>删除 {n} 段</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="446" />
            <source>Move segment up</source>
            <translation>上移段</translation>
        </message>
        <message>
            <location filename="../../ui/models/segment_model.py" line="446" />
            <source>Move segment down</source>
            <translation>下移段</translation>
        </message>
    </context>
    <context>
        <name>SelfTestDialog</name>
        <message>
            <location filename="../../ui/dialogs/selftest_dialog.py" line="97" />
            <source>The controller's register map</source>
            <translation>控制器的寄存器映射</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/selftest_dialog.py" line="99" />
            <source>Check</source>
            <translation>检查</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/selftest_dialog.py" line="99" />
            <source>Result</source>
            <translation>结果</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/selftest_dialog.py" line="99" />
            <source>What was read</source>
            <translation>读到的内容</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/selftest_dialog.py" line="99" />
            <source>Likely fix</source>
            <translation>可能的解决办法</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/selftest_dialog.py" line="101" />
            <source>Check &amp;again</source>
            <translation>重新检查(&amp;A)</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/selftest_dialog.py" line="104" />
            <source>Only reads: nothing is written to the controller and nothing moves. The check runs by itself after every connect.</source>
            <translation>只读取：不向控制器写入任何内容，机器人不会运动。每次连接后都会自动检查。</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/selftest_dialog.py" line="120" />
            <source>Not checked yet: connect to a controller first.</source>
            <translation>尚未检查：请先连接控制器。</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/selftest_dialog.py" line="126" />
            <source>Not connected to a controller: nothing can be read.</source>
            <translation>未连接控制器：无法读取。</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/selftest_dialog.py" line="130" />
            <source>Reading the controller's registers…</source>
            <translation>正在读取控制器的寄存器…</translation>
        </message>
        <message>
            <location filename="../../ui/dialogs/selftest_dialog.py" line="135" />
            <source>The registers could not be read: {why}</source>
            <translation>无法读取寄存器：{why}</translation>
        </message>
    </context>
    <context>
        <name>SelfTestWords</name>
        <message>
            <location filename="../../ui/selftest_words.py" line="32" />
            <source>Pose X Y Z A B C (word order)</source>
            <translation>位姿 X Y Z A B C（字序）</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="33" />
            <source>Pose from the joints (robot model)</source>
            <translation>由关节角算出的位姿（机器人模型）</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="34" />
            <source>Controller mode (560)</source>
            <translation>控制器模式（560）</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="35" />
            <source>Program state (561)</source>
            <translation>程序状态（561）</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="36" />
            <source>Alarm bits (562)</source>
            <translation>报警位（562）</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="37" />
            <source>Date and time (576–579)</source>
            <translation>日期和时间（576–579）</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="38" />
            <source>Command status (GV291)</source>
            <translation>命令返回状态（GV291）</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="39" />
            <source>Program motion mode (447)</source>
            <translation>程序运动模式（447）</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="40" />
            <source>Program speed ratio (449)</source>
            <translation>程序速度比例（449）</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="41" />
            <source>Status registers (560–583)</source>
            <translation>状态寄存器（560–583）</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="44" />
            <source>matches</source>
            <translation>一致</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="45" />
            <source>does not match</source>
            <translation>不一致</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="46" />
            <source>not checked</source>
            <translation>未检查</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="49" />
            <source>The controller refused the read of registers {what} (Modbus exception {exception}).</source>
            <translation>控制器拒绝读取寄存器 {what}（Modbus 异常 {exception}）。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="52" />
            <source>X Y Z A B C are all 0: nothing to judge.</source>
            <translation>X Y Z A B C 全为 0：无法判断。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="53" />
            <source>Read {order}, the pose is one a robot can stand at: {pose}.</source>
            <translation>按{order}读取，位姿是机器人可以到达的：{pose}。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="56" />
            <source>Read {order}, the pose is {pose}; read {other}, it is {other_pose}.</source>
            <translation>按{order}读取，位姿为 {pose}；按{other}读取，则为 {other_pose}。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="59" />
            <source>X Y Z A B C read either way are no pose a robot stands at: {pose}.</source>
            <translation>X Y Z A B C 无论按哪种字序读取都不是机器人可能的位姿：{pose}。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="62" />
            <source>No robot model to compute the pose with.</source>
            <translation>没有用于计算位姿的机器人模型。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="63" />
            <source>The controller publishes no joint angles in GV250–GV255 (a TeachPad extension): the pose cannot be computed from them.</source>
            <translation>控制器未在 GV250–GV255 中发布关节角（TeachPad 扩展）：无法由关节角计算位姿。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="68" />
            <source>The robot model “{model}” computes the pose from the joints within {mm} mm and {deg}°.</source>
            <translation>机器人模型“{model}”由关节角算出的位姿与控制器的位姿相差不超过 {mm} mm 和 {deg}°。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="72" />
            <source>The robot model “{model}” does not compute the pose from the joints read {order}; read {other}, it does.</source>
            <translation>按{order}读取时，机器人模型“{model}”由关节角算不出控制器的位姿；按{other}读取则可以。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="77" />
            <source>The joints or the pose are not finite numbers, read either way.</source>
            <translation>无论按哪种字序读取，关节角或位姿都不是有限数值。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="80" />
            <source>The robot model “{model}” computes the pose from the joints only if the controller reports {reading}; TeachPad reads mm, degrees and fixed-axis X-Y-Z angles.</source>
            <translation>只有当控制器报告的是{reading}时，机器人模型“{model}”才能由关节角算出其位姿；TeachPad 按毫米、度和固定轴 X-Y-Z 角读取。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="85" />
            <source>The robot model “{model}” puts the pose {mm} mm and {deg}° from the one the controller reports.</source>
            <translation>机器人模型“{model}”算出的位姿与控制器报告的位姿相差 {mm} mm 和 {deg}°。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="89" />
            <source>Register {register} = {value} ({meaning}).</source>
            <translation>寄存器 {register} = {value}（{meaning}）。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="90" />
            <source>Register {register} = {value}: not one of its table's values ({allowed}).</source>
            <translation>寄存器 {register} = {value}：不在其取值表中（{allowed}）。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="93" />
            <source>Register 562 = {value} (alarms on: {alarms}).</source>
            <translation>寄存器 562 = {value}（当前报警：{alarms}）。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="94" />
            <source>Register 562 = {value}: bits {bits} are none of the five documented alarms.</source>
            <translation>寄存器 562 = {value}：位 {bits} 不属于文档中的五种报警。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="97" />
            <source>The date/time registers are all 0.</source>
            <translation>日期/时间寄存器全为 0。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="98" />
            <source>The controller's clock reads {clock}, this PC's {pc}.</source>
            <translation>控制器时钟为 {clock}，本机时钟为 {pc}。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="99" />
            <source>The date/time words ({raw}) read as {other} are this PC's time ({other_clock}).</source>
            <translation>日期/时间字（{raw}）按{other}读取才是本机时间（{other_clock}）。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="102" />
            <source>The date/time words ({raw}) are no date in either layout.</source>
            <translation>日期/时间字（{raw}）按两种格式都不是有效日期。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="105" />
            <source>The controller's clock reads {clock}: {apart} ahead of this PC's ({pc}).</source>
            <translation>控制器时钟为 {clock}：比本机时钟（{pc}）快 {apart}。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="108" />
            <source>The controller's clock reads {clock}: {apart} behind this PC's ({pc}).</source>
            <translation>控制器时钟为 {clock}：比本机时钟（{pc}）慢 {apart}。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="111" />
            <source>GV291 = {value} ({meaning}).</source>
            <translation>GV291 = {value}（{meaning}）。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="112" />
            <source>GV291's words ({raw}) are no status code read {order}; read {other}, they are {other_value}.</source>
            <translation>GV291 的两个字（{raw}）按{order}读取不是状态码；按{other}读取则为 {other_value}。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="116" />
            <source>GV291's words ({raw}) are none of the documented status codes.</source>
            <translation>GV291 的两个字（{raw}）不是文档中的任何状态码。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="119" />
            <source>Register {register} = {value} (within {low}–{high}).</source>
            <translation>寄存器 {register} = {value}（在 {low}–{high} 之内）。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="120" />
            <source>Register {register} = {value}: outside {low}–{high}.</source>
            <translation>寄存器 {register} = {value}：超出 {low}–{high}。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="125" />
            <source>Set the register profile's {field} to {value} (Safety → Register profile…), then connect again.</source>
            <translation>请把寄存器配置的{field}设为{value}（安全 → 寄存器配置…），然后重新连接。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="129" />
            <source>Check the unit id, and that this controller has the vendor document's register map.</source>
            <translation>请检查从站地址，并确认该控制器使用厂家文档中的寄存器映射。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="132" />
            <source>Not a register profile setting: set the controller to mm, degrees and fixed-axis X-Y-Z angles, or tell the TeachPad team.</source>
            <translation>这不是寄存器配置中的设置：请把控制器设为毫米、度和固定轴 X-Y-Z 角，或告知 TeachPad 团队。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="137" />
            <source>Load the robot model of this arm (3D view → Robot model…), or check the joint registers.</source>
            <translation>请加载该机械臂的机器人模型（3D 视图 → 机器人模型…），或检查关节寄存器。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="141" />
            <source>Set the controller's clock (or this PC's): not a register profile setting.</source>
            <translation>请校准控制器的时钟（或本机时钟）：这不是寄存器配置中的设置。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="146" />
            <source>word order</source>
            <translation>字序</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="147" />
            <source>date/time layout</source>
            <translation>日期/时间格式</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="150" />
            <source>split words (year, month·day)</source>
            <translation>分两个寄存器（年、月·日）</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="151" />
            <source>packed 32-bit values</source>
            <translation>打包的 32 位值</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="154" />
            <source>the position in metres</source>
            <translation>以米为单位的位置</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="155" />
            <source>the joints in radians</source>
            <translation>以弧度为单位的关节角</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="156" />
            <source>A B C as rotating-axis X-Y'-Z'' angles (fixed Z-Y-X)</source>
            <translation>动轴 X-Y'-Z'' 角（即定轴 Z-Y-X）表示的 A B C</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="159" />
            <source>A B C as Z-Y-Z Euler angles</source>
            <translation>Z-Y-Z 欧拉角表示的 A B C</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="160" />
            <source>A B C in radians</source>
            <translation>以弧度为单位的 A B C</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="162" />
            <source>{n} days</source>
            <translation>{n} 天</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="163" />
            <source>{n} h</source>
            <translation>{n} 小时</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="164" />
            <source>{n} s</source>
            <translation>{n} 秒</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="165" />
            <source>none</source>
            <translation>无</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="166" />
            <source>The register map matches the register profile: {match} checks matched, {unchecked} not checked.</source>
            <translation>寄存器映射与寄存器配置一致：{match} 项一致，{unchecked} 项未检查。</translation>
        </message>
        <message>
            <location filename="../../ui/selftest_words.py" line="170" />
            <source>The register map does not match the register profile: {mismatch} of {total} checks do not match.</source>
            <translation>寄存器映射与寄存器配置不一致：{total} 项检查中有 {mismatch} 项不一致。</translation>
        </message>
    </context>
    <context>
        <name>StatusPanel</name>
        <message>
            <location filename="../../ui/panels/status_panel.py" line="244" />
            <source>Link</source>
            <translation>通信链路</translation>
        </message>
        <message>
            <location filename="../../ui/panels/status_panel.py" line="245" />
            <source>Controller</source>
            <translation>控制器</translation>
        </message>
        <message>
            <location filename="../../ui/panels/status_panel.py" line="246" />
            <location filename="../../ui/panels/status_panel.py" line="322" />
            <source>Alarms</source>
            <translation>报警</translation>
        </message>
        <message>
            <location filename="../../ui/panels/status_panel.py" line="246" />
            <location filename="../../ui/panels/status_panel.py" line="322" />
            <source>Alarms (last known)</source>
            <translation>报警（最后已知）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/status_panel.py" line="248" />
            <source>State:</source>
            <translation>状态：</translation>
        </message>
        <message>
            <location filename="../../ui/panels/status_panel.py" line="249" />
            <source>RTT:</source>
            <translation>往返时间：</translation>
        </message>
        <message>
            <location filename="../../ui/panels/status_panel.py" line="250" />
            <source>Mode:</source>
            <translation>模式：</translation>
        </message>
        <message>
            <location filename="../../ui/panels/status_panel.py" line="251" />
            <source>Program:</source>
            <translation>程序：</translation>
        </message>
        <message>
            <location filename="../../ui/panels/status_panel.py" line="252" />
            <source>Last command:</source>
            <translation>上一条命令：</translation>
        </message>
        <message>
            <location filename="../../ui/panels/status_panel.py" line="253" />
            <source>Clock:</source>
            <translation>系统时间：</translation>
        </message>
        <message>
            <location filename="../../ui/panels/status_panel.py" line="254" />
            <source>Drift:</source>
            <translation>时差：</translation>
        </message>
        <message>
            <location filename="../../ui/panels/status_panel.py" line="255" />
            <source>Round-trip time of the last poll</source>
            <translation>最近一次轮询的往返时间</translation>
        </message>
        <message>
            <location filename="../../ui/panels/status_panel.py" line="263" />
            <source>Register 562 bit {bit}</source>
            <translation>寄存器 562 第 {bit} 位</translation>
        </message>
        <message>
            <location filename="../../ui/panels/status_panel.py" line="264" />
            <source>Register 562 bits with no documented meaning</source>
            <translation>寄存器 562 中未定义含义的位</translation>
        </message>
        <message>
            <location filename="../../ui/panels/status_panel.py" line="269" />
            <source>disconnected</source>
            <translation>未连接</translation>
        </message>
        <message>
            <location filename="../../ui/panels/status_panel.py" line="278" />
            <source>none yet</source>
            <translation>暂无</translation>
        </message>
        <message>
            <location filename="../../ui/panels/status_panel.py" line="388" />
            <source>unknown</source>
            <translation>未知</translation>
        </message>
        <message>
            <location filename="../../ui/panels/status_panel.py" line="406" />
            <source>other bits: {bits}</source>
            <translation>其他位：{bits}</translation>
        </message>
        <message>
            <location filename="../../ui/panels/status_panel.py" line="408" />
            <source>other bits</source>
            <translation>其他位</translation>
        </message>
        <message>
            <location filename="../../ui/panels/status_panel.py" line="420" />
            <source>monitor only: writes blocked</source>
            <translation>仅监视：禁止写入</translation>
        </message>
        <message>
            <location filename="../../ui/panels/status_panel.py" line="256" />
            <location filename="../../ui/panels/status_panel.py" line="428" />
            <source>{ms} ms</source>
            <translation>{ms} ms</translation>
        </message>
        <message>
            <location filename="../../ui/panels/status_panel.py" line="445" />
            <source>GV291 code: {code}</source>
            <translation>GV291 返回码：{code}</translation>
        </message>
        <message>
            <location filename="../../ui/panels/status_panel.py" line="453" />
            <source>Raw words {first}..{last}: {words}</source>
            <translation>寄存器 {first}..{last} 原始值：{words}</translation>
        </message>
        <message>
            <location filename="../../ui/panels/status_panel.py" line="457" />
            <source>Controller clock minus PC clock</source>
            <translation>控制器时间减去电脑时间</translation>
        </message>
        <message>
            <location filename="../../ui/panels/status_panel.py" line="461" />
            <source>invalid date/time</source>
            <translation>日期/时间无效</translation>
        </message>
        <message>
            <location filename="../../ui/panels/status_panel.py" line="258" />
            <location filename="../../ui/panels/status_panel.py" line="467" />
            <source>{drift} s</source>
            <translation>{drift} 秒</translation>
        </message>
        <message>
            <location filename="../../ui/panels/status_panel.py" line="259" />
            <location filename="../../ui/panels/status_panel.py" line="470" />
            <source>{value} (stale)</source>
            <translation>{value}（已过期）</translation>
        </message>
    </context>
    <context>
        <name>StepPanel</name>
        <message>
            <location filename="../../ui/panels/step_panel.py" line="202" />
            <source>Frame:</source>
            <translation>坐标系：</translation>
        </message>
        <message>
            <location filename="../../ui/panels/step_panel.py" line="203" />
            <source>Joint frame</source>
            <translation>关节坐标系</translation>
        </message>
        <message>
            <location filename="../../ui/panels/step_panel.py" line="204" />
            <source>Base frame</source>
            <translation>基坐标系</translation>
        </message>
        <message>
            <location filename="../../ui/panels/step_panel.py" line="205" />
            <source>Speed:</source>
            <translation>速度：</translation>
        </message>
        <message>
            <location filename="../../ui/panels/step_panel.py" line="206" />
            <source>Expected speed of the incremental move (GV225)</source>
            <translation>增量运动的期望速度（GV225）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/step_panel.py" line="207" />
            <source>Increment per click (mm or °)</source>
            <translation>每次点击的增量（mm 或 °）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/step_panel.py" line="208" />
            <source>Incremental move</source>
            <translation>增量运动</translation>
        </message>
        <message>
            <location filename="../../ui/panels/step_panel.py" line="209" />
            <source>Exact offset</source>
            <translation>精确偏移量</translation>
        </message>
        <message>
            <location filename="../../ui/panels/step_panel.py" line="210" />
            <source>Move by values</source>
            <translation>按数值运动</translation>
        </message>
        <message>
            <location filename="../../ui/panels/step_panel.py" line="211" />
            <source>Move every axis by its exact offset in one incremental move</source>
            <translation>以一次增量运动使各轴移动其精确偏移量</translation>
        </message>
        <message>
            <location filename="../../ui/panels/step_panel.py" line="212" />
            <source>Clear values</source>
            <translation>清除数值</translation>
        </message>
        <message>
            <location filename="../../ui/panels/step_panel.py" line="213" />
            <source>External axes J7–J11</source>
            <translation>外部轴 J7–J11</translation>
        </message>
        <message>
            <location filename="../../ui/panels/step_panel.py" line="214" />
            <source>Show the external axes; while hidden their offsets are 0</source>
            <translation>显示外部轴；隐藏时其偏移量为 0</translation>
        </message>
        <message>
            <location filename="../../ui/panels/step_panel.py" line="243" />
            <source>rpm</source>
            <translation>转/分</translation>
        </message>
        <message>
            <location filename="../../ui/panels/step_panel.py" line="243" />
            <source>mm/s</source>
            <translation>mm/s</translation>
        </message>
        <message>
            <location filename="../../ui/panels/step_panel.py" line="305" />
            <source>{axis} limits {lo} … {hi} {unit} (its position is not known)</source>
            <translation>{axis} 限位 {lo} … {hi} {unit}（当前位置未知）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/step_panel.py" line="309" />
            <source>{axis} limits {lo} … {hi} {unit}, now at {at} {unit}</source>
            <translation>{axis} 限位 {lo} … {hi} {unit}，当前位于 {at} {unit}</translation>
        </message>
        <message>
            <location filename="../../ui/panels/step_panel.py" line="376" />
            <source>Move by {moves} at {speed} {unit}?</source>
            <translation>以 {speed} {unit} 运动 {moves}？</translation>
        </message>
        <message>
            <location filename="../../ui/panels/step_panel.py" line="380" />
            <source>(capped by reduced speed; {asked} {unit} set)</source>
            <translation>（受降速模式限制；设定为 {asked} {unit}）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/step_panel.py" line="383" />
            <source>Confirm incremental move</source>
            <translation>确认增量运动</translation>
        </message>
        <message>
            <location filename="../../ui/panels/step_panel.py" line="430" />
            <source>→ {cap} {unit}</source>
            <translation>→ {cap} {unit}</translation>
        </message>
        <message>
            <location filename="../../ui/panels/step_panel.py" line="433" />
            <source>Reduced speed: a step goes out at {cap} {unit} at most (one joint; less when several joints move together)</source>
            <translation>降速模式：增量运动最多以 {cap} {unit} 发出（单个关节；多个关节同时运动时更低）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/step_panel.py" line="437" />
            <source>Reduced speed: a step goes out at {cap} {unit} at most</source>
            <translation>降速模式：增量运动最多以 {cap} {unit} 发出</translation>
        </message>
        <message>
            <location filename="../../ui/panels/step_panel.py" line="302" />
            <location filename="../../ui/panels/step_panel.py" line="409" />
            <source>°</source>
            <translation>°</translation>
        </message>
        <message>
            <location filename="../../ui/panels/step_panel.py" line="302" />
            <location filename="../../ui/panels/step_panel.py" line="409" />
            <source>mm</source>
            <translation>mm</translation>
        </message>
    </context>
    <context>
        <name>TrafficModel</name>
        <message>
            <location filename="../../ui/models/traffic_model.py" line="103" />
            <source>Time</source>
            <translation>时间</translation>
        </message>
        <message>
            <location filename="../../ui/models/traffic_model.py" line="104" />
            <source>Dir</source>
            <translation>方向</translation>
        </message>
        <message>
            <location filename="../../ui/models/traffic_model.py" line="105" />
            <source>Bytes</source>
            <translation>字节</translation>
        </message>
        <message>
            <location filename="../../ui/models/traffic_model.py" line="106" />
            <source>Meaning</source>
            <translation>含义</translation>
        </message>
        <message>
            <location filename="../../ui/models/traffic_model.py" line="108" />
            <source>→ Tx</source>
            <translation>→ 发送</translation>
        </message>
        <message>
            <location filename="../../ui/models/traffic_model.py" line="109" />
            <source>← Rx</source>
            <translation>← 接收</translation>
        </message>
        <message>
            <location filename="../../ui/models/traffic_model.py" line="382" />
            <source>{n} bytes</source>
            <translation>{n} 字节</translation>
        </message>
    </context>
    <context>
        <name>TrafficPanel</name>
        <message>
            <location filename="../../ui/panels/traffic_panel.py" line="161" />
            <source>Filter: bytes or meaning</source>
            <translation>过滤：字节或含义</translation>
        </message>
        <message>
            <location filename="../../ui/panels/traffic_panel.py" line="162" />
            <source>Hide polls</source>
            <translation>隐藏轮询</translation>
        </message>
        <message>
            <location filename="../../ui/panels/traffic_panel.py" line="164" />
            <source>Hide the periodic reads of 412.. (pose) and 560.. (status)</source>
            <translation>隐藏对 412..（位姿）和 560..（状态）的周期读取</translation>
        </message>
        <message>
            <location filename="../../ui/panels/traffic_panel.py" line="166" />
            <source>Pause capture</source>
            <translation>暂停抓包</translation>
        </message>
        <message>
            <location filename="../../ui/panels/traffic_panel.py" line="167" />
            <source>Stop recording frames (the worker stops building them)</source>
            <translation>停止记录报文（后台不再生成报文记录）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/traffic_panel.py" line="168" />
            <source>Clear</source>
            <translation>清空</translation>
        </message>
        <message>
            <location filename="../../ui/panels/traffic_panel.py" line="169" />
            <source>Export…</source>
            <translation>导出…</translation>
        </message>
        <message>
            <location filename="../../ui/panels/traffic_panel.py" line="298" />
            <source>Export traffic</source>
            <translation>导出通信报文</translation>
        </message>
        <message>
            <location filename="../../ui/panels/traffic_panel.py" line="300" />
            <source>CSV files (*.csv);;Text files (*.txt);;All files (*)</source>
            <translation>CSV 文件 (*.csv);;文本文件 (*.txt);;所有文件 (*)</translation>
        </message>
        <message>
            <location filename="../../ui/panels/traffic_panel.py" line="171" />
            <location filename="../../ui/panels/traffic_panel.py" line="329" />
            <source>{n} frames</source>
            <translation>{n} 帧</translation>
        </message>
        <message>
            <location filename="../../ui/panels/traffic_panel.py" line="331" />
            <source>{shown} of {n} frames shown</source>
            <translation>显示 {shown} / {n} 帧</translation>
        </message>
        <message>
            <location filename="../../ui/panels/traffic_panel.py" line="333" />
            <source>capture paused</source>
            <translation>抓包已暂停</translation>
        </message>
    </context>
    <context>
        <name>TrafficWords</name>
        <message>
            <location filename="../../ui/traffic_words.py" line="30" />
            <source>read {what}</source>
            <translation>读取 {what}</translation>
        </message>
        <message>
            <location filename="../../ui/traffic_words.py" line="31" />
            <source>write acknowledged: {what}</source>
            <translation>写入已应答：{what}</translation>
        </message>
        <message>
            <location filename="../../ui/traffic_words.py" line="32" />
            <source>acknowledged: {what}</source>
            <translation>已应答：{what}</translation>
        </message>
        <message>
            <location filename="../../ui/traffic_words.py" line="33" />
            <source>malformed: {what}</source>
            <translation>格式错误：{what}</translation>
        </message>
        <message>
            <location filename="../../ui/traffic_words.py" line="34" />
            <source>write {what}</source>
            <translation>写入 {what}</translation>
        </message>
        <message>
            <location filename="../../ui/traffic_words.py" line="37" />
            <source>exception {code}: {name}</source>
            <translation>异常 {code}：{name}</translation>
        </message>
        <message>
            <location filename="../../ui/traffic_words.py" line="41" />
            <source>truncated frame</source>
            <translation>帧不完整</translation>
        </message>
        <message>
            <location filename="../../ui/traffic_words.py" line="42" />
            <source>exception (code missing)</source>
            <translation>异常（缺少异常码）</translation>
        </message>
        <message>
            <location filename="../../ui/traffic_words.py" line="46" />
            <source>pose X..C</source>
            <translation>位姿 X..C</translation>
        </message>
        <message>
            <location filename="../../ui/traffic_words.py" line="47" />
            <source>pose, ext axes, joints</source>
            <translation>位姿、外部轴、关节</translation>
        </message>
        <message>
            <location filename="../../ui/traffic_words.py" line="48" />
            <source>ext axes J7..J11</source>
            <translation>外部轴 J7..J11</translation>
        </message>
        <message>
            <location filename="../../ui/traffic_words.py" line="49" />
            <source>joints J1..J6</source>
            <translation>关节 J1..J6</translation>
        </message>
        <message>
            <location filename="../../ui/traffic_words.py" line="50" />
            <source>status</source>
            <translation>状态</translation>
        </message>
        <message>
            <location filename="../../ui/traffic_words.py" line="51" />
            <location filename="../../ui/traffic_words.py" line="58" />
            <source>clock</source>
            <translation>时钟</translation>
        </message>
        <message>
            <location filename="../../ui/traffic_words.py" line="52" />
            <source>command status</source>
            <translation>命令状态</translation>
        </message>
        <message>
            <location filename="../../ui/traffic_words.py" line="55" />
            <source>mode</source>
            <translation>模式</translation>
        </message>
        <message>
            <location filename="../../ui/traffic_words.py" line="56" />
            <source>program</source>
            <translation>程序</translation>
        </message>
        <message>
            <location filename="../../ui/traffic_words.py" line="57" />
            <source>alarms</source>
            <translation>报警</translation>
        </message>
        <message>
            <location filename="../../ui/traffic_words.py" line="64" />
            <source>{n} registers {rest}</source>
            <translation>{n} 个寄存器 {rest}</translation>
        </message>
        <message>
            <location filename="../../ui/traffic_words.py" line="65" />
            <source>registers {rest}</source>
            <translation>寄存器 {rest}</translation>
        </message>
        <message>
            <location filename="../../ui/traffic_words.py" line="68" />
            <source>invalid</source>
            <translation>无效</translation>
        </message>
        <message>
            <location filename="../../ui/traffic_words.py" line="69" />
            <source>none</source>
            <translation>无</translation>
        </message>
        <message>
            <location filename="../../ui/traffic_words.py" line="97" />
            <source>: </source>
            <translation>：</translation>
        </message>
    </context>
    <context>
        <name>UnderWay</name>
        <message>
            <location filename="../../ui/controllers/link_guard.py" line="89" />
            <source>a program is running</source>
            <extracomment>mm or degrees: a smaller change between two polled poses is noise, not motion s: the arm counts as moving while the last good poll came within this of its last movement (a stale pose that was still changing when the link went counts as moving)</extracomment>
            <translation>程序正在运行</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/link_guard.py" line="91" />
            <source>a program is paused</source>
            <translation>程序已暂停</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/link_guard.py" line="93" />
            <source>a jog is held</source>
            <translation>点动按住中</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/link_guard.py" line="97" />
            <source>{operation}: under way</source>
            <translation>{operation}：正在进行</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/link_guard.py" line="99" />
            <source>a plan run is under way</source>
            <translation>规划正在运行</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/link_guard.py" line="102" />
            <source>the arm is moving</source>
            <translation>机械臂正在运动</translation>
        </message>
        <message>
            <location filename="../../ui/controllers/link_guard.py" line="104" />
            <source>the arm was moving when last seen</source>
            <translation>最后一次看到时机械臂正在运动</translation>
        </message>
    </context>
    <context>
        <name>View3DCanvas</name>
        <message>
            <location filename="../../ui/panels/view3d_canvas.py" line="337" />
            <source>grid %1 mm</source>
            <translation>网格 %1 mm</translation>
        </message>
    </context>
    <context>
        <name>View3DHost</name>
        <message>
            <location filename="../../ui/panels/view3d_host.py" line="137" />
            <source>3D</source>
            <translation>3D</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_host.py" line="138" />
            <location filename="../../ui/panels/view3d_host.py" line="147" />
            <location filename="../../ui/panels/view3d_host.py" line="159" />
            <source>3D view</source>
            <translation>3D 视图</translation>
        </message>
    </context>
    <context>
        <name>View3DPanel</name>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="230" />
            <source>Top</source>
            <translation>俯视</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="231" />
            <source>Front</source>
            <translation>正视</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="232" />
            <source>Side</source>
            <translation>侧视</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="233" />
            <source>Iso</source>
            <translation>轴测</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="237" />
            <source>Look at the scene from a preset direction</source>
            <translation>从预设方向观察场景</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="238" />
            <source>Fit all</source>
            <translation>全部显示</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="240" />
            <source>Show the arm, the points and the plan (the view follows them again until you move it)</source>
            <translation>显示机械臂、点位和轨迹（在您移动视图之前，视图会自动跟随它们）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="242" />
            <source>Fit plan</source>
            <translation>缩放至轨迹</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="243" />
            <source>Show the selected plan's path and its points</source>
            <translation>显示所选轨迹的路径及其点位</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="244" />
            <source>Orthographic</source>
            <translation>正交投影</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="245" />
            <source>Parallel projection (no perspective)</source>
            <translation>平行投影（无透视）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="246" />
            <source>Robot model…</source>
            <translation>机器人模型…</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="247" />
            <source>Load another robot model profile (JSON; engineer)</source>
            <translation>加载其他机器人模型配置文件（JSON；需工程师）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="249" />
            <source>Beside the planner</source>
            <translation>在规划器旁显示</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="250" />
            <source>Show the 3D view next to the planner, not in its own tab</source>
            <translation>将 3D 视图显示在规划器旁边，而不是单独的标签页</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="252" />
            <source>Drag: rotate · Shift or right drag: pan · Wheel: zoom · Click a point: select it</source>
            <translation>拖动：旋转 · Shift 或右键拖动：平移 · 滚轮：缩放 · 单击点位：选中</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="286" />
            <location filename="../../ui/panels/view3d_panel.py" line="335" />
            <source>Robot model not loaded: %1</source>
            <translation>未加载机器人模型：%1</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="295" />
            <location filename="../../ui/panels/view3d_panel.py" line="297" />
            <source>Robot model: %1</source>
            <translation>机器人模型：%1</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="298" />
            <source>File: %1</source>
            <translation>文件：%1</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="300" />
            <source>Shipped with TeachPad</source>
            <translation>TeachPad 自带</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="304" />
            <source>Not compared with the controller (no joint angles from it)</source>
            <translation>未与控制器比对（控制器未提供关节角）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="307" />
            <source>Agrees with the controller's pose (within %1 mm, %2°)</source>
            <translation>与控制器的位姿一致（误差在 %1 mm、%2° 以内）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="341" />
            <source>Load a robot model profile</source>
            <translation>加载机器人模型配置文件</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="341" />
            <source>Robot model profiles (*.json)</source>
            <translation>机器人模型配置文件 (*.json)</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="454" />
            <source>dry run: nothing is sent</source>
            <translation>空运行：不发送任何指令</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="456" />
            <source>no pose: home position shown</source>
            <translation>无位姿：显示原点姿态</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="458" />
            <source>estimate (from the pose, no joint angles)</source>
            <translation>估算（由位姿求得，无关节角）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="460" />
            <source>pose out of the model's reach</source>
            <translation>位姿超出模型可达范围</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="462" />
            <source>past a joint limit</source>
            <translation>超出关节限位</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="464" />
            <source>stale</source>
            <translation>数据过期</translation>
        </message>
        <message>
            <location filename="../../ui/panels/view3d_panel.py" line="467" />
            <source>the robot model disagrees with the controller</source>
            <translation>机器人模型与控制器不一致</translation>
        </message>
        <message numerus="yes">
            <location filename="../../ui/panels/view3d_panel.py" line="524" />
            <source>Out of the robot model's reach: %n point(s) (%1)</source>
            <translation>
                <numerusform>超出机器人模型的可达范围：%n 个点（%1）</numerusform>
            </translation>
        </message>
        <message numerus="yes">
            <location filename="../../ui/panels/view3d_panel.py" line="532" />
            <source>the path leaves the reach in %n segment(s) (%1)</source>
            <translation>
                <numerusform>轨迹在 %n 个段中超出可达范围（%1）</numerusform>
            </translation>
        </message>
    </context>
    <context>
        <name>WatchListHost</name>
        <message>
            <location filename="../../ui/window_watch_list.py" line="184" />
            <source>Not connected, or monitor-only: nothing can be written</source>
            <translation>未连接或处于仅监视模式：无法写入</translation>
        </message>
        <message>
            <location filename="../../ui/window_watch_list.py" line="189" />
            <location filename="../../ui/window_watch_list.py" line="212" />
            <source>Write value</source>
            <translation>写入数值</translation>
        </message>
        <message>
            <location filename="../../ui/window_watch_list.py" line="190" />
            <source>New value of {what} ({type}):</source>
            <translation>{what}（{type}）的新值：</translation>
        </message>
        <message>
            <location filename="../../ui/window_watch_list.py" line="204" />
            <source>Write {value} to {what} ({where_reg}) on the controller at {endpoint}?

It holds {old} now.</source>
            <translation>将 {value} 写入控制器 {endpoint} 上的 {what}（{where_reg}）？

当前值为 {old}。</translation>
        </message>
        <message>
            <location filename="../../ui/window_watch_list.py" line="210" />
            <source>(not read)</source>
            <translation>（未读取）</translation>
        </message>
        <message>
            <location filename="../../ui/window_watch_list.py" line="239" />
            <source>The value was not written: {why}</source>
            <translation>数值未写入：{why}</translation>
        </message>
        <message>
            <location filename="../../ui/window_watch_list.py" line="245" />
            <source>Export the watch list</source>
            <translation>导出监视列表</translation>
        </message>
        <message>
            <location filename="../../ui/window_watch_list.py" line="247" />
            <source>CSV files (*.csv)</source>
            <translation>CSV 文件 (*.csv)</translation>
        </message>
        <message>
            <location filename="../../ui/window_watch_list.py" line="255" />
            <source>Cannot write {path}: {error}</source>
            <translation>无法写入 {path}：{error}</translation>
        </message>
        <message>
            <location filename="../../ui/window_watch_list.py" line="264" />
            <source>Watch list</source>
            <translation>监视列表</translation>
        </message>
        <message>
            <location filename="../../ui/window_watch_list.py" line="265" />
            <source>&amp;Watch list</source>
            <translation>监视列表(&amp;W)</translation>
        </message>
    </context>
    <context>
        <name>WatchListModel</name>
        <message>
            <location filename="../../ui/models/watch_list_model.py" line="74" />
            <source>Name</source>
            <translation>名称</translation>
        </message>
        <message>
            <location filename="../../ui/models/watch_list_model.py" line="74" />
            <source>Where</source>
            <translation>位置</translation>
        </message>
        <message>
            <location filename="../../ui/models/watch_list_model.py" line="74" />
            <source>Type</source>
            <translation>类型</translation>
        </message>
        <message>
            <location filename="../../ui/models/watch_list_model.py" line="74" />
            <source>Value</source>
            <translation>数值</translation>
        </message>
        <message>
            <location filename="../../ui/models/watch_list_model.py" line="74" />
            <source>Age</source>
            <translation>时效</translation>
        </message>
        <message>
            <location filename="../../ui/models/watch_list_model.py" line="90" />
            <source>Registers: {raw}</source>
            <translation>寄存器：{raw}</translation>
        </message>
        <message>
            <location filename="../../ui/models/watch_list_model.py" line="102" />
            <source>reg {n}</source>
            <translation>寄存器 {n}</translation>
        </message>
        <message>
            <location filename="../../ui/models/watch_list_model.py" line="105" />
            <source>bits</source>
            <translation>位</translation>
        </message>
        <message>
            <location filename="../../ui/models/watch_list_model.py" line="110" />
            <source>not read yet</source>
            <translation>尚未读取</translation>
        </message>
        <message>
            <location filename="../../ui/models/watch_list_model.py" line="112" />
            <source>error</source>
            <translation>错误</translation>
        </message>
        <message>
            <location filename="../../ui/models/watch_list_model.py" line="115" />
            <source>stale ({age:.1f} s)</source>
            <translation>过时（{age:.1f} 秒）</translation>
        </message>
        <message>
            <location filename="../../ui/models/watch_list_model.py" line="116" />
            <source>{age:.1f} s</source>
            <translation>{age:.1f} 秒</translation>
        </message>
    </context>
    <context>
        <name>WatchListPanel</name>
        <message>
            <location filename="../../ui/panels/watch_list_panel.py" line="189" />
            <source>{what} is in the list already</source>
            <translation>{what} 已在列表中</translation>
        </message>
        <message>
            <location filename="../../ui/panels/watch_list_panel.py" line="192" />
            <source>At most {n} values can be watched</source>
            <translation>最多可监视 {n} 个数值</translation>
        </message>
        <message>
            <location filename="../../ui/panels/watch_list_panel.py" line="236" />
            <source>Not connected, or monitor-only: nothing can be written</source>
            <translation>未连接或处于仅监视模式：无法写入</translation>
        </message>
        <message>
            <location filename="../../ui/panels/watch_list_panel.py" line="239" />
            <source>Write a value to the selected GV or register (confirmed, audited)</source>
            <translation>向所选 GV 或寄存器写入数值（需确认，记入审计）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/watch_list_panel.py" line="323" />
            <source>Register</source>
            <translation>寄存器</translation>
        </message>
        <message>
            <location filename="../../ui/panels/watch_list_panel.py" line="324" />
            <source>float32</source>
            <translation>float32</translation>
        </message>
        <message>
            <location filename="../../ui/panels/watch_list_panel.py" line="324" />
            <source>int16</source>
            <translation>int16</translation>
        </message>
        <message>
            <location filename="../../ui/panels/watch_list_panel.py" line="324" />
            <source>bits</source>
            <translation>位</translation>
        </message>
        <message>
            <location filename="../../ui/panels/watch_list_panel.py" line="327" />
            <source>A GV (two registers, 2n and 2n+1) or a holding register by its address</source>
            <translation>GV（两个寄存器 2n 和 2n+1）或按地址指定的保持寄存器</translation>
        </message>
        <message>
            <location filename="../../ui/panels/watch_list_panel.py" line="331" />
            <source>float32: two registers in the register profile's word order; int16: one register, signed; bits: one register as 16 bits</source>
            <translation>float32：两个寄存器，按寄存器配置的字序；int16：一个寄存器，有符号；bits：一个寄存器，显示 16 位</translation>
        </message>
        <message>
            <location filename="../../ui/panels/watch_list_panel.py" line="335" />
            <source>Name (optional)</source>
            <translation>名称（可选）</translation>
        </message>
        <message>
            <location filename="../../ui/panels/watch_list_panel.py" line="336" />
            <source>Add</source>
            <translation>添加</translation>
        </message>
        <message>
            <location filename="../../ui/panels/watch_list_panel.py" line="337" />
            <source>Remove</source>
            <translation>移除</translation>
        </message>
        <message>
            <location filename="../../ui/panels/watch_list_panel.py" line="338" />
            <source>Write value…</source>
            <translation>写入数值…</translation>
        </message>
        <message>
            <location filename="../../ui/panels/watch_list_panel.py" line="339" />
            <source>Export CSV…</source>
            <translation>导出 CSV…</translation>
        </message>
        <message>
            <location filename="../../ui/panels/watch_list_panel.py" line="346" />
            <source>seconds ago</source>
            <translation>秒前</translation>
        </message>
    </context>
    <context>
        <name>WindowActions</name>
        <message>
            <location filename="../../ui/window_actions.py" line="185" />
            <source>Show &amp;monitor</source>
            <translation>显示监视(&amp;M)</translation>
        </message>
        <message>
            <location filename="../../ui/window_actions.py" line="185" />
            <source>Show &amp;points</source>
            <translation>显示点位(&amp;P)</translation>
        </message>
        <message>
            <location filename="../../ui/window_actions.py" line="185" />
            <source>Show p&amp;lanner</source>
            <translation>显示轨迹规划(&amp;L)</translation>
        </message>
        <message>
            <location filename="../../ui/window_actions.py" line="189" />
            <source>&amp;File</source>
            <translation>文件(&amp;F)</translation>
        </message>
        <message>
            <location filename="../../ui/window_actions.py" line="190" />
            <source>&amp;Edit</source>
            <translation>编辑(&amp;E)</translation>
        </message>
        <message>
            <location filename="../../ui/window_actions.py" line="191" />
            <source>&amp;Motion</source>
            <translation>运动(&amp;M)</translation>
        </message>
        <message>
            <location filename="../../ui/window_actions.py" line="192" />
            <source>&amp;View</source>
            <translation>视图(&amp;V)</translation>
        </message>
        <message>
            <location filename="../../ui/window_actions.py" line="193" />
            <source>&amp;Language</source>
            <translation>语言(&amp;L)</translation>
        </message>
        <message>
            <location filename="../../ui/window_actions.py" line="194" />
            <source>&amp;Help</source>
            <translation>帮助(&amp;H)</translation>
        </message>
        <message>
            <location filename="../../ui/window_actions.py" line="195" />
            <location filename="../../ui/window_actions.py" line="196" />
            <source>Toolbar</source>
            <translation>工具栏</translation>
        </message>
        <message>
            <location filename="../../ui/window_actions.py" line="197" />
            <source>&amp;Connect…</source>
            <translation>连接(&amp;C)…</translation>
        </message>
        <message>
            <location filename="../../ui/window_actions.py" line="198" />
            <source>Connect to a controller (Ctrl+K)</source>
            <translation>连接控制器（Ctrl+K）</translation>
        </message>
        <message>
            <location filename="../../ui/window_actions.py" line="199" />
            <source>&amp;Disconnect</source>
            <translation>断开(&amp;D)</translation>
        </message>
        <message>
            <location filename="../../ui/window_actions.py" line="200" />
            <source>&amp;Reconnect</source>
            <translation>重新连接(&amp;R)</translation>
        </message>
        <message>
            <location filename="../../ui/window_actions.py" line="202" />
            <source>Connect again to the last controller, with the same settings</source>
            <translation>以相同设置重新连接到上次的控制器</translation>
        </message>
        <message>
            <location filename="../../ui/window_actions.py" line="204" />
            <source>&amp;Quit</source>
            <translation>退出(&amp;Q)</translation>
        </message>
        <message>
            <location filename="../../ui/window_actions.py" line="205" />
            <source>&amp;Stop</source>
            <translation>停止(&amp;S)</translation>
        </message>
        <message>
            <location filename="../../ui/window_actions.py" line="206" />
            <source>Stop all motion (Esc)</source>
            <translation>停止所有运动（Esc）</translation>
        </message>
        <message>
            <location filename="../../ui/window_actions.py" line="207" />
            <source>&amp;Pause</source>
            <translation>暂停(&amp;P)</translation>
        </message>
        <message>
            <location filename="../../ui/window_actions.py" line="208" />
            <source>Pause the current move or program (F6)</source>
            <translation>暂停当前运动或程序（F6）</translation>
        </message>
        <message>
            <location filename="../../ui/window_actions.py" line="209" />
            <source>&amp;Resume</source>
            <translation>继续(&amp;R)</translation>
        </message>
        <message>
            <location filename="../../ui/window_actions.py" line="210" />
            <source>Resume the paused move or program (F7)</source>
            <translation>继续已暂停的运动或程序（F7）</translation>
        </message>
        <message>
            <location filename="../../ui/window_actions.py" line="211" />
            <source>&amp;About TeachPad</source>
            <translation>关于 TeachPad(&amp;A)</translation>
        </message>
        <message>
            <location filename="../../ui/window_actions.py" line="212" />
            <source>&amp;Touch mode</source>
            <translation>触摸模式(&amp;T)</translation>
        </message>
        <message>
            <location filename="../../ui/window_actions.py" line="213" />
            <source>Bigger motion buttons and an on-screen keypad for numbers</source>
            <translation>更大的运动按钮，数字输入使用屏幕小键盘</translation>
        </message>
    </context>
    <context>
        <name>WordOrderWords</name>
        <message>
            <location filename="../../ui/messages_word_order.py" line="27" />
            <source>low word first (CDAB)</source>
            <translation>低字在前（CDAB）</translation>
        </message>
        <message>
            <location filename="../../ui/messages_word_order.py" line="28" />
            <source>high word first (ABCD)</source>
            <translation>高字在前（ABCD）</translation>
        </message>
        <message>
            <location filename="../../ui/messages_word_order.py" line="30" />
            <source>The controller's floats look word-swapped: set the register profile's word order to {order} (Safety → Register profile…), then connect again.</source>
            <translation>控制器的浮点数看起来高低字颠倒了：请把寄存器配置的字序设为{order}（安全 → 寄存器配置…），然后重新连接。</translation>
        </message>
        <message>
            <location filename="../../ui/messages_word_order.py" line="35" />
            <source>Until then every position and speed read or sent is wrong. Read {current}, the pose is {read}; read {other}, it is {swapped}.</source>
            <translation>在此之前，读到和发出的每个位置与速度都是错的。按{current}读取，位姿为 {read}；按{other}读取，则为 {swapped}。</translation>
        </message>
    </context>
</TS>
