function R=Rot(fi)
% R=Rot(fi)
% Obliczanie macierzy rotacji - przypadek płaski (2x2)
% Wejście:
% fi - kat fi (w radianach).
% Wyjście:
% R - macierz kosinusów kierunkowych.

R=[cos(fi) -sin(fi);sin(fi) cos(fi)];
