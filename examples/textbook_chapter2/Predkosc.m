function dq=Predkosc(q,t)
% dq=Predkosc(q,t)
% Procedura do rozwiązywania zadania o prędkości.
% Zadanie o położeniu musi być rozwiązane wcześniej.
% Wejście:
%   q - współrzędne absolutne układu wieloczłonowego,
%   t - chwila, dla której poszukiwane jest rozwiązanie.
% Wyjście:
%   dq - obliczone pochodne współrzędnych absolutnych względem czasu.

% Prawa strona układu równań liniowych - pochodne więzów względem czasu.
Ft=[zeros(8,1);-2*t];

% Macierz układu równań
Fq=Jakobian(q);

% Obliczenie prędkości
dq=-Fq\Ft;
