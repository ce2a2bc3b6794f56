% Dane.m - plik zawierający dane o wymiarach mechanizmu

a=1; b=5; c=4; % Wymiary mechanizmu:
sA0=[0;0]; sB1=[0;0]; % Para obrotowa 0-1
sA1=[a;0]; sB2=[0;0]; % Para obrotowa 1-2
sA2=[b;0]; sB3=[0;0]; % Para obrotowa 2-3
f0=0; v0=[0;1]; sA3=[0;0]; sB0=[0;c]; % Para postępową 3-0
