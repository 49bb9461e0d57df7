#include <iostream>
int main() { std::cout << "omniloc\n"; return 0; }
