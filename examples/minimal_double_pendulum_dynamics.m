function [M,C,G] = minimal_double_pendulum_dynamics(in1,in2,m1,m2,l1,r1,r2,I1,I2,g)
%MINIMAL_DOUBLE_PENDULUM_DYNAMICS
%    [M,C,G] = MINIMAL_DOUBLE_PENDULUM_DYNAMICS(IN1,IN2,M1,M2,L1,R1,R2,I1,I2,G)
%
%    The minimal double pendulum's M(q), C(q,dq) and G(q) (theta1 from the horizontal, theta2
%    relative to link 1) in the layout MATLAB's matlabFunction writes: a worked example of
%    pendverify, read by examples/minimal_double_pendulum_matlab.toml (docs/matlab.md).

theta1 = in1(1,:);
theta2 = in1(2,:);
dtheta1 = in2(1,:);
dtheta2 = in2(2,:);
t2 = l1.*m2;
t3 = r2.*t2;
t4 = t3.*cos(theta2);
t5 = r2.^2;
t6 = I2 + m2.*t5;
t7 = t4 + t6;
t8 = t3.*sin(theta2);
t9 = m2.*r2.*cos(theta1 + theta2);
M = reshape([I1 + I2 + m1.*r1.^2 + m2.*(l1.^2 + t5) + 2*t4,t7,t7,t6],[2,2]);
if nargout > 1
    C = reshape([-dtheta2.*t8,dtheta1.*t8,-t8.*(dtheta1 + dtheta2),0],[2,2]);
end
if nargout > 2
    G = [g.*(t9 + (m1.*r1 + t2).*cos(theta1));g.*t9];
end
